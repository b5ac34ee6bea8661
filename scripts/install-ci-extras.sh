#!/usr/bin/env bash
# Installs what the reliability checks of CI need beyond scripts/install-deps.sh (Debian 12):
# clang 14 with its sanitizer and libFuzzer runtimes (libclang-rt-14-dev) and valgrind.
# Idempotent: does nothing when every package is already installed. Not needed for the README's
# Quick start or scripts/test.sh.
set -euo pipefail
packages=(clang libclang-rt-14-dev valgrind)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-ci-extras: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-ci-extras: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
