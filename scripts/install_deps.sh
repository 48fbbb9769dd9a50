#!/usr/bin/env bash
# Installs the Debian 12 packages colmap-fvs needs (only those missing). Idempotent; fast when
# everything is there. Runs apt as root or through sudo. Arguments name extra, optional
# packages (scripts/demo.sh asks for ffmpeg this way; the build and tests never need it).
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config git
  colmap
  libeigen3-dev libceres-dev libcgal-dev libboost-graph-dev
  libtorch-dev
  libopenimageio-dev openimageio-tools python3-imath
  qtbase5-dev libqt5opengl5-dev xvfb xauth
  libgtest-dev libsqlite3-dev nlohmann-json3-dev
)
if [[ $# -gt 0 ]]; then
  PACKAGES=("$@")
fi
if [[ "${FVS_NO_GUI:-0}" == "1" ]]; then
  PACKAGES=("${PACKAGES[@]/qtbase5-dev}")
  PACKAGES=("${PACKAGES[@]/libqt5opengl5-dev}")
fi

missing=()
for p in "${PACKAGES[@]}"; do
  [[ -z "$p" ]] && continue
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null; then SUDO="sudo"; else
    echo "ERROR: install_deps: need root or sudo to install: ${missing[*]}" >&2
    exit 1
  fi
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install_deps: done"
