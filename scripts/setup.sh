#!/usr/bin/env bash
# Installs the Debian packages iesrgs needs (only the missing ones), then configures and builds.
#   scripts/setup.sh            release build in build/
#   scripts/setup.sh --cli      the same, the iesrgs binary only (no tests, no benchmarks)
#   scripts/setup.sh --asan     AddressSanitizer + UBSan build in build-asan/
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=build
options=(-DCMAKE_BUILD_TYPE=Release)
targets=()
case "${1:-}" in
  --asan)
    build_dir=build-asan
    # Line tables (-g1) are all the sanitizers' reports need; full debug information of
    # LibTorch's templates would double the compile time. The CUDA kernels are left out: nvcc
    # does not take these sanitizers, and compute-sanitizer checks them on a GPU machine.
    options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
             -DIESRGS_SANITIZE=ON -DIESRGS_BENCH=OFF -DIESRGS_CUDA=OFF) ;;
  --cli) targets=(--target iesrgs) ;;
  "") ;;
  *) echo "error: unknown option '$1' (setup.sh takes --cli or --asan, or nothing)" >&2; exit 2 ;;
esac

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libtorch-dev          # tensors, autograd, Adam, .pth checkpoints
  libcli11-dev nlohmann-json3-dev libstb-dev libfmt-dev libspdlog-dev zlib1g-dev libzstd-dev
  libgtest-dev libgmock-dev libbenchmark-dev
)
# npm fetches the super-resolution model that `auto` takes without SAFMN's checkpoint (below); a
# Node.js install may already ship it.
command -v npm >/dev/null || PACKAGES+=(npm)

scripts/apt-install.sh "${PACKAGES[@]}"

# The default super-resolution prior: the MIT-licensed pre-trained ESRGAN models of UpscalerJS
# (TensorFlow.js layers models), looked up at run time in $IESRGS_NPM_DIR or third_party/npm.
# Thick (115 MB) is the one `--sr-model auto` uses without SAFMN's checkpoint; slim (4 MB) is checked against TensorFlow.js
# (kSetupEsrganVariants in src/priors/sr/esrgan.hpp). One command for both: npm would remove the
# other unsaved package.
npm_dir=${IESRGS_NPM_DIR:-third_party/npm}
packages=$npm_dir/node_modules/@upscalerjs
if [ ! -f "$packages/esrgan-thick/models/x4/model.json" ] ||
   [ ! -f "$packages/esrgan-slim/models/x4/model.json" ]; then
  # Not fatal: without them `--sr-model auto` takes SAFMN's checkpoint or bicubic, and their tests
  # skip.
  npm install --prefix "$npm_dir" --no-save --omit=peer --no-audit --no-fund \
    @upscalerjs/esrgan-thick@1.0.0 @upscalerjs/esrgan-slim@1.0.0 ||
    echo "warning: npm could not install the ESRGAN models into $npm_dir; run setup again" \
      "to retry (until then --sr-model auto falls back to SAFMN or bicubic)" >&2
fi

# Ninja, not Make: Make compiles no source of a target before the libraries it links are built,
# Ninja only links later, which keeps both cores busy (docs/BENCHMARKS.md, "Build and CI time").
# A folder configured by another generator is configured afresh (everything recompiles).
cache=$build_dir/CMakeCache.txt
if [ -f "$cache" ] && ! grep -qx "CMAKE_GENERATOR:INTERNAL=Ninja" "$cache"; then
  echo "setup: $build_dir was configured for another generator; configuring it again for Ninja"
  rm -rf "$cache" "$build_dir/CMakeFiles"
fi
cmake -S . -B "$build_dir" -G Ninja "${options[@]}" >/dev/null
cmake --build "$build_dir" -j "$(nproc)" "${targets[@]}"
echo "setup: built $build_dir/iesrgs"
