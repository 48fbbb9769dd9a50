#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (-DFVS_SANITIZE=ON),
# in its own build folder: run it after every change to a parser or the renderer and
# record the result and date in doc/reliability.md.
#   scripts/sanitize.sh [ctest args...]       e.g. scripts/sanitize.sh -R delaunay
# A sanitizer report fails the test that printed it (halt_on_error); leaks in libraries we
# do not build are suppressed by tests/lsan.supp, never ours. The first build takes long on
# 2 cores (everything, with instrumentation); ccache keeps the next ones short.
set -euo pipefail
cd "$(dirname "$0")/.."
export FVS_BUILD_DIR="${FVS_SANITIZE_BUILD_DIR:-build-asan}"
# RelWithDebInfo: reports with file:line; -O2 keeps the suite's run time bearable.
scripts/build.sh -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFVS_SANITIZE=ON
# fast_unwind_on_malloc=0: the frame-pointer unwinder stops in libraries built without
# frame pointers (libpng under OpenImageIO), so a leak there showed no OpenImageIO frame
# and tests/lsan.supp could not match it; the full unwinder sees the whole stack.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:abort_on_error=0:detect_stack_use_after_return=0:fast_unwind_on_malloc=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
cd "$FVS_BUILD_DIR"
start=$(date +%s)
status=0
# (Instrumented code runs 2-3x slower: the build triples every test's time limit.)
ctest --output-on-failure -j "${FVS_JOBS:-$(nproc)}" "$@" || status=$?
echo "sanitized suite: exit ${status} after $(( $(date +%s) - start )) s on $(nproc) cores," \
  "$(date -u +%F)"
exit "$status"
