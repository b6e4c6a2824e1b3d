#!/bin/bash
# Install the Debian 12 packages talus needs, and nothing else.
# Does nothing (and needs no network) when everything is already present.
set -euo pipefail
PKGS=(cmake ninja-build g++ make libdeal.ii-dev libeigen3-dev gmsh libgmsh-dev libhdf5-dev
      libgtest-dev openmpi-bin ccache gnuplot-nox python3 python3-vtk9 clang-format-14)
missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "talus: installing missing Debian packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" != "0" ]; then
  if command -v sudo >/dev/null; then SUDO="sudo"; else
    echo "talus: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq "${missing[@]}"
