#!/usr/bin/env bash
# Builds every libFuzzer harness (fuzz/<name>_fuzzer.cpp) with clang and runs each one for
# SECONDS seconds (default 60). Each corpus grows in fuzz/corpus-<name>/ (git-ignored), seeded
# from fuzz/corpus/<name>_fuzzer/, tests/data/<name>/ and tests/data/*/<name>/ where they exist;
# fuzz/<name>_fuzzer.dict is used as a dictionary where it exists. Crashing inputs are saved as
# fuzz/crash-* (git-ignored).
# Exits non-zero when any harness found a failure.
#
# usage: scripts/fuzz.sh [SECONDS] [NAME...]    (NAME: run only these harnesses, e.g. colmap)
set -euo pipefail

seconds=${1:-60}
shift || true
root=$(cd "$(dirname "$0")/.." && pwd)
build=${IESRGS_FUZZ_BUILD:-$root/build-fuzz}

names=("$@")
if [[ ${#names[@]} -eq 0 ]]; then
  for source in "$root"/fuzz/*_fuzzer.cpp; do
    [[ -e $source ]] && names+=("$(basename "$source" _fuzzer.cpp)")
  done
fi
if [[ ${#names[@]} -eq 0 ]]; then
  echo "no harnesses in $root/fuzz" >&2
  exit 1
fi

# libFuzzer's runtime is in libclang-rt-14-dev, which clang only recommends.
[ -n "${CXX:-}" ] || "$root/scripts/apt-install.sh" clang libclang-rt-14-dev

targets=()
for name in "${names[@]}"; do targets+=("iesrgs_${name}_fuzzer"); done
# The parsers need no CUDA kernels (and nvcc may not take this clang as its host compiler).
CXX=${CXX:-clang++} cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DIESRGS_FUZZ=ON -DIESRGS_TESTS=OFF -DIESRGS_BENCH=OFF -DIESRGS_CUDA=OFF >/dev/null
cmake --build "$build" -j"${JOBS:-2}" --target "${targets[@]}"

status=0
for name in "${names[@]}"; do
  corpus=$root/fuzz/corpus-$name
  mkdir -p "$corpus"
  options=(-max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$root/fuzz/")
  dict=$root/fuzz/${name}_fuzzer.dict
  [[ -f $dict ]] && options+=(-dict="$dict")
  seeds=()
  for seed in "$root/fuzz/corpus/${name}_fuzzer" "$root/tests/data/$name" "$root"/tests/data/*/"$name"; do
    [[ -d $seed ]] && seeds+=("$seed")
  done
  echo "== $name: ${seconds}s, corpus $corpus"
  "$build/fuzz/iesrgs_${name}_fuzzer" "${options[@]}" "$corpus" "${seeds[@]}" || status=1
done
exit $status
