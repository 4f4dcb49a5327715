#!/usr/bin/env bash
# Installs the given Debian packages that are not installed yet (sudo when not root).
#   scripts/apt-install.sh PACKAGE...
set -euo pipefail
missing=()
for package in "$@"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
    missing+=("$package")
done
((${#missing[@]})) || exit 0
echo "installing ${missing[*]}"
sudo=()
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo >/dev/null; then
    echo "error: these Debian packages are missing: ${missing[*]}; install them as root" \
      "(apt-get install ${missing[*]}) or install sudo, then run this again" >&2
    exit 1
  fi
  sudo=(sudo)
fi
# Through env: sudo drops the caller's environment, and apt would then ask its questions.
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
