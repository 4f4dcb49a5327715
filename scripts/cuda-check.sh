#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, the CUDA toolkit, CMake and a C++ compiler: builds the
# rasterizer kernels alone (no LibTorch), runs the CUDA tests, runs them again under
# compute-sanitizer (memcheck, racecheck), then the benchmark at 800x800.
#   scripts/cuda-check.sh [--deps DIR] [benchmark options, e.g. --cpu]
#   scripts/cuda-check.sh --fetch-deps DIR
# The build needs fmt and GoogleTest. Where the GPU machine has neither and cannot install them,
# --fetch-deps downloads their Debian packages into DIR (on a Debian machine with apt), and
# --deps DIR unpacks them into a temporary prefix for the build.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--fetch-deps" ]; then
  mkdir -p "$2"
  (cd "$2" && apt-get download libfmt-dev libfmt9 libgtest-dev libgmock-dev)
  exit
fi
options=(-DIESRGS_KERNELS_ONLY=ON -DIESRGS_CUDA=ON -DCMAKE_BUILD_TYPE=Release)
if [ "${1:-}" = "--deps" ]; then
  prefix=$(mktemp -d)
  for deb in "$2"/*.deb; do dpkg-deb -x "$deb" "$prefix"; done
  options+=("-DCMAKE_PREFIX_PATH=$prefix/usr")
  shift 2
fi

nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
cmake -S . -B build-cuda "${options[@]}" >/dev/null
cmake --build build-cuda -j "$(nproc)"
tests=build-cuda/iesrgs_cuda_tests
status=0
"$tests" || status=1
compute-sanitizer --tool memcheck --error-exitcode 1 "$tests" || status=1
# Racecheck is slow; the posed-camera scene runs both blend kernels over every kind of tile.
compute-sanitizer --tool racecheck --error-exitcode 1 "$tests" \
  --gtest_filter='*PosedCamera*:*OpaqueSplats*' || status=1
build-cuda/bench/cuda/iesrgs_cuda_bench "$@"
exit $status
