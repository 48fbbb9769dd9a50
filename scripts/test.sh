#!/usr/bin/env bash
# Sets up (Debian packages), builds, and runs the whole test suite with ctest; then the
# fuzz smoke step: every libFuzzer target of tests/fuzz over its seed corpus and 5 s of
# mutations (build-fuzz/, clang with ASan + UBSan; about 10 minutes to build on 2 cores,
# 1 to run), so that a reader that regressed shows. FVS_FUZZ_SMOKE=0 leaves it out.
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ="${FVS_FUZZ_SMOKE:-1}"
if [[ "$FUZZ" == "1" ]]; then
  scripts/install_deps.sh
  # clang and libFuzzer's runtime, beside the packages of the build.
  scripts/install_deps.sh clang libclang-rt-14-dev
else
  scripts/install_deps.sh
fi
scripts/build.sh
(
  cd "${FVS_BUILD_DIR:-build}"
  ctest --output-on-failure -j "${FVS_JOBS:-$(nproc)}" "$@"
)
[[ "$FUZZ" == "1" ]] || exit 0
scripts/fuzz.sh --smoke
