#!/usr/bin/env bash
# Sets up (packages + build), then runs the main job on the embedded default: the built-in
# synthetic scene. Outputs go to demo/ (or the folder given as the first argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-demo}"
scripts/setup.sh
build/iesrgs synth -o "$out/scene" --size 200 --views 60 --test-views 20 --seed 1
build/iesrgs info "$out/scene" --load-images
