#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, the CUDA toolkit, CMake and a C++ compiler: builds iesrgs with
# its CUDA kernels and checks them.
#   scripts/cuda-check.sh [--deps DIR] [--kernels-only] [--quick] [benchmark options, e.g. --cpu]
#   scripts/cuda-check.sh --fetch-deps DIR
# The full build links the LibTorch of the machine's PyTorch (python3 -c 'import torch'), runs the
# main suite's GPU tests (rendering, SSIM, Adam and training through LibTorch, against the CPU),
# trains the same synthetic scene on the CPU and on the GPU and prints both results, then runs the
# whole suite.
# --kernels-only builds the kernels alone (no LibTorch) and ends with their benchmark at 800x800.
# Both run the kernels' own tests, then again under compute-sanitizer (memcheck, racecheck) unless
# --quick.
# Where the GPU machine lacks the Debian libraries and cannot install them, --fetch-deps downloads
# their packages into DIR (on a Debian machine with apt), and --deps DIR unpacks them into
# /tmp/iesrgs-deps for the build and the binaries (their run path points there).
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--fetch-deps" ]; then
  mkdir -p "$2"
  (cd "$2" && apt-get download libfmt-dev libfmt9 libgtest-dev libgmock-dev libspdlog-dev \
    libspdlog1.10 nlohmann-json3-dev libcli11-dev libstb-dev libstb0 zlib1g-dev zlib1g \
    libzstd-dev libzstd1)
  exit
fi
prefix_path=()
if [ "${1:-}" = "--deps" ]; then
  prefix=/tmp/iesrgs-deps
  rm -rf "$prefix"
  for deb in "$2"/*.deb; do dpkg-deb -x "$deb" "$prefix"; done
  # Absolute links (libz.so -> /lib/...) must point into the prefix.
  find "$prefix" -type l -lname '/*' | while read -r link; do
    ln -sfn "$prefix$(readlink "$link")" "$link"
  done
  prefix_path+=("$prefix/usr")
  shift 2
fi
torch_prefix() { python3 -c 'import torch; print(torch.utils.cmake_prefix_path)'; }
# Which OpenMP and CUDA runtimes a binary loads: PyTorch's wheels bring their own.
runtimes() { ldd "$1" | grep -E 'gomp|omp5|libomp|cudart' || true; }
kernels_only=false
if [ "${1:-}" = "--kernels-only" ]; then
  kernels_only=true
  shift
fi
sanitize=true
if [ "${1:-}" = "--quick" ]; then
  sanitize=false
  shift
fi

# IESRGS_KERNELS_ONLY is set either way: the cache would keep a --kernels-only run's ON.
options=(-DIESRGS_CUDA=ON -DCMAKE_BUILD_TYPE=Release -DIESRGS_BENCH=OFF -DIESRGS_KERNELS_ONLY=OFF)
targets=(--target iesrgs_cuda_tests)
if $kernels_only; then
  options+=(-DIESRGS_KERNELS_ONLY=ON -DIESRGS_BENCH=ON)
  targets+=(iesrgs_cuda_bench)
else
  prefix_path+=("$(torch_prefix)")
  targets+=(iesrgs iesrgs_tests)
fi
prefixes=$(IFS=';'; echo "${prefix_path[*]:-}")

nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
cmake -S . -B build-cuda "${options[@]}" "-DCMAKE_PREFIX_PATH=$prefixes" >/dev/null
cmake --build build-cuda -j "$(nproc)" "${targets[@]}"
tests=build-cuda/iesrgs_cuda_tests
[ -x "$tests" ] || tests=build-cuda/tests/iesrgs_cuda_tests
status=0
"$tests" || status=1
if ! $kernels_only; then
  runtimes build-cuda/tests/iesrgs_tests
  build-cuda/tests/iesrgs_tests --gtest_filter='*Cuda*' || status=1
  # The same training on both devices: the GPU's test PSNR should match the CPU's.
  scene=$(mktemp -d)
  build-cuda/iesrgs synth -o "$scene/data" --size 128 --views 40 --test-views 8 >/dev/null
  for device in cpu cuda; do
    build-cuda/iesrgs train "$scene/data" -o "$scene/$device" --device "$device" --preset fast \
      --iterations 1000 | grep -E '^(device|done)' || status=1
  done
  rm -rf "$scene"
  # The whole suite, whose command-line tests train and render with --device auto: on the GPU.
  ctest --test-dir build-cuda --output-on-failure -j "$(nproc)" || status=1
fi
if $sanitize; then
  compute-sanitizer --tool memcheck --error-exitcode 1 "$tests" || status=1
  # Racecheck is slow; the posed-camera scene runs both blend kernels over every kind of tile.
  compute-sanitizer --tool racecheck --error-exitcode 1 "$tests" \
    --gtest_filter='*PosedCamera*:*OpaqueSplats*' || status=1
fi
if $kernels_only; then build-cuda/bench/cuda/iesrgs_cuda_bench "$@"; fi
exit $status
