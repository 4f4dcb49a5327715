#!/usr/bin/env bash
# Sets up (packages + build), then runs the whole test suite through ctest.
#   scripts/test.sh          release build
#   scripts/test.sh --asan   the same suite under AddressSanitizer + UBSan
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh "$@"
build_dir=build
[ "${1:-}" = "--asan" ] && build_dir=build-asan
# ASan's leak checker does not work under ptrace-restricted sandboxes, so leaks are not checked
# (ASAN_OPTIONS=detect_leaks=1 turns it on where it works).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}"
# ctest starts the longest suites first once it knows their times from an earlier run; a first
# sanitizer run borrows the release run's, so that its end-to-end suites do not finish it alone.
costs=Testing/Temporary/CTestCostData.txt
if [ "$build_dir" != build ] && [ ! -f "$build_dir/$costs" ] && [ -f "build/$costs" ]; then
  mkdir -p "$(dirname "$build_dir/$costs")"
  cp "build/$costs" "$build_dir/$costs"
fi
# A build configured without tests must fail here, not pass with none run.
ctest --test-dir "$build_dir" --output-on-failure --no-tests=error -j "$(nproc)"
# ctest counts a skipped test as passed: name them, so that a missing data file or GPU shows.
skipped=$(sed -n 's/^\[  SKIPPED \] \([^ ]*\) (.*/\1/p' "$build_dir/Testing/Temporary/LastTest.log" |
  sort -u)
if [ -n "$skipped" ]; then
  echo "skipped ($(echo "$skipped" | wc -l); ctest counts them as passed):"
  echo "$skipped" | sed 's/^/  /'
fi
