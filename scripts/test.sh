#!/usr/bin/env bash
# Sets up (Debian packages), builds, and runs the whole test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
cd "${FVS_BUILD_DIR:-build}"
ctest --output-on-failure -j "${FVS_JOBS:-$(nproc)}" "$@"
