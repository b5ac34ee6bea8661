#!/usr/bin/env bash
# Installs the Debian packages pcl_probcollision needs to build, test and benchmark, plus any
# extra package names given as arguments. Idempotent: does nothing when all are installed.
set -euo pipefail
packages=(cmake make g++ pkg-config doxygen libpcl-dev libeigen3-dev libflann-dev libboost-dev
          libgtest-dev libbenchmark-dev libfcl-dev liboctomap-dev gnuplot-nox
          pybind11-dev python3-dev python3-numpy python3-pytest python3-dask python3-distributed
          python3-open3d "$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
