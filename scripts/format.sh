#!/usr/bin/env bash
# Formats every C++/CUDA source git tracks or would track (new files too) with the repository's
# .clang-format.
#   scripts/format.sh           rewrite the files in place
#   scripts/format.sh --check   change nothing; fail and name the files that need formatting
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || scripts/apt-install.sh clang-format
mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.cpp' '*.hpp' '*.cu' '*.cuh')
# With no file, clang-format would read standard input and check nothing.
if [ ${#files[@]} -eq 0 ]; then
  echo "error: git lists no source files here (not a git checkout, or git refuses it)" >&2
  exit 1
fi
if [ "${1:-}" = "--check" ]; then
  clang-format --dry-run --Werror "${files[@]}"
else
  clang-format -i "${files[@]}"
fi
