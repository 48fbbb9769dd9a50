#!/usr/bin/env bash
# Builds the libFuzzer targets (FVS_FUZZ=ON, clang, ASan + UBSan) into build-fuzz/ and
# runs each for SECONDS (default 60) on its corpus, build-fuzz/corpus/<target> (kept
# between runs, grown from the seeds). Prints per target the executions, the coverage
# (edges, "cov") and the findings; a finding's input is saved under
# build-fuzz/findings/<target>/ (reproduce: build-fuzz/bin/fuzz/<target>_fuzzer FILE).
#   scripts/fuzz.sh [SECONDS] [TARGET...]      e.g. scripts/fuzz.sh 120 ply safetensors
#   FVS_FUZZ_RUNS=10000000 scripts/fuzz.sh 7200   issue 18's proof: each target stops
#       at 10 million executions or 2 hours, whichever comes first
#   scripts/fuzz.sh --smoke                    the CI step (scripts/test.sh): the ctest
#       of build-fuzz, every target over its seeds and 5 s of mutations (about a minute)
# Exits 1 when any target had a finding. doc/reliability.md ("Fuzzing") has the results.
set -euo pipefail
cd "$(dirname "$0")/.."

SMOKE=0
if [[ "${1:-}" == "--smoke" ]]; then
  SMOKE=1
  shift
fi
SECONDS_PER_TARGET="${1:-60}"
RUNS="${FVS_FUZZ_RUNS:-0}"  # > 0: also stop a target after this many executions
shift || true
BUILD_DIR="${FVS_FUZZ_BUILD_DIR:-build-fuzz}"
JOBS="${FVS_JOBS:-$(nproc)}"
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
export CCACHE_SLOPPINESS="pch_defines,time_macros,include_file_mtime,include_file_ctime"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"

if [[ ! -f "$BUILD_DIR/build.ninja" ]]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DFVS_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$BUILD_DIR" -j "$JOBS"

if [[ $SMOKE == 1 ]]; then
  ctest --test-dir "$BUILD_DIR" -L fuzz --output-on-failure -j "$JOBS"
  exit $?
fi

if [[ $# -gt 0 ]]; then
  targets=("$@")
else
  targets=()
  for f in "$BUILD_DIR"/bin/fuzz/*_fuzzer; do
    name="$(basename "$f")"
    targets+=("${name%_fuzzer}")
  done
fi

# Leaks are findings too (ASan's default here; image_fuzzer.cc turns them off for
# OpenImageIO's sake). Symbolized reports name our file and line.
export ASAN_OPTIONS="${ASAN_OPTIONS:-symbolize=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"
status=0
printf '%-20s %12s %8s %8s %8s  %s\n' target executions seconds cov corpus findings
for name in "${targets[@]}"; do
  corpus="$BUILD_DIR/corpus/$name"
  findings="$BUILD_DIR/findings/$name"
  log="$BUILD_DIR/logs/$name.log"
  mkdir -p "$corpus" "$findings" "$(dirname "$log")"
  # -timeout: an input taking over 10 s is a hang; -rss_limit_mb: over 2.5 GB is an
  # out-of-memory finding (OSS-Fuzz's limits).
  # Keywords and edge numbers of the text formats (tests/fuzz/dicts/): random bytes
  # rarely spell "render_width" or 1e30.
  extra=()
  if ((RUNS > 0)); then extra+=(-runs="$RUNS"); fi
  if [[ -f "tests/fuzz/dicts/$name.dict" ]]; then extra+=(-dict="tests/fuzz/dicts/$name.dict"); fi
  start=$(date +%s)
  set +e
  "$BUILD_DIR/bin/fuzz/${name}_fuzzer" -max_total_time="$SECONDS_PER_TARGET" \
    -timeout=10 -rss_limit_mb=2560 -print_final_stats=1 "${extra[@]}" \
    -artifact_prefix="$findings/" "$corpus" "$BUILD_DIR/seeds/$name" >"$log" 2>&1
  rc=$?
  set -e
  seconds=$(($(date +%s) - start))
  execs="$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | awk '{print $2}' | tail -1)"
  cov="$(grep -o 'cov: [0-9]*' "$log" | awk '{print $2}' | tail -1)"
  corp="$(find "$corpus" -type f | wc -l)"
  found="none"
  if [[ $rc -ne 0 ]]; then
    status=1
    artifact="$(grep -o "Test unit written to [^ ]*" "$log" | tail -1 | cut -d' ' -f5)"
    kind="$(grep -m1 -oE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer): [a-z-]+|runtime error: .*|fvs::Error with a bad message|terminate called.*' "$log" | head -1)"
    found="${kind:-exit $rc} -> ${artifact:-$log}"
  fi
  printf '%-20s %12s %8s %8s %8s  %s\n' "$name" "${execs:-?}" "$seconds" "${cov:-?}" \
    "$corp" "$found"
done
exit $status
