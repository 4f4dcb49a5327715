#!/usr/bin/env bash
# Sets up (packages + build), then runs IE-SRGS end to end on the embedded default: the built-in
# synthetic scene at 128x128, x4 from 32x32 LR views, with the best SR prior at hand (SAFMN when
# its checkpoint is present, else the ESRGAN model setup installs). Prints the PSNR/SSIM table of
# bicubic-3DGS, internal only, external only and IE-SRGS. Outputs go to demo/ (or the folder
# given as the first argument); rerunning reuses every finished stage.
set -euo pipefail
out=demo  # in the repository; a folder given is taken from where the script is called
[ -z "${1:-}" ] || out=$(realpath -m -- "$1")
cd "$(dirname "$0")/.."
scripts/setup.sh --cli
# A scene already there is reused, as the run reuses its stages: synth writes transforms_train.json
# last, so the file means a whole scene, and synth refuses a folder made by a version before
# synth.json.
if [ -f "$out/scene/transforms_train.json" ]; then
  echo "reusing the synthetic scene in $out/scene"
else
  build/iesrgs synth -o "$out/scene" --size 128 --views 40 --test-views 10 --seed 1
fi
# A short CPU schedule, and fewer random starting points than 3DGS's 100k for a scene this small.
build/iesrgs run "$out/scene" -o "$out/run" --scale 4 --rows demo --lpips none \
  --iterations 1500 --set random_points=20000 \
  --internal-iterations 1500 --internal-set random_points=20000
