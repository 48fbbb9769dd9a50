#!/usr/bin/env bash
# Configures and builds colmap-fvs into build/ (Release, Ninja, ccache). Extra arguments go to
# CMake's configure step, e.g. scripts/build.sh -DFVS_WITH_GUI=OFF.
set -euo pipefail
cd "$(dirname "$0")/.."

export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
# Precompiled headers need these for ccache to hit.
export CCACHE_SLOPPINESS="pch_defines,time_macros,include_file_mtime,include_file_ctime"
# Paths relative to the checkout, so a fresh clone elsewhere hits the same cache.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
export CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-5G}"

BUILD_DIR="${FVS_BUILD_DIR:-build}"
JOBS="${FVS_JOBS:-$(nproc)}"
if [[ ! -f "$BUILD_DIR/build.ninja" || $# -gt 0 ]]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
fi
cmake --build "$BUILD_DIR" -j "$JOBS"
