#!/usr/bin/env bash
# One prepared run on the GPU machine (issue 20; doc/training.md "On a GPU machine").
#
#   scripts/gpu/run.sh [MINUTES] [trainer flags...]
#
# From a fresh copy of the working tree plus the carried gpu_data/ (made here by
# scripts/gpu/pack_training_set.sh) and, to resume, gpu_resume/:
#   1. unpacks gpu_data/packed.tar.xz (the packed training set, quarter resolution) and,
#      when the machine lacks them, gpu_data/vendor.tar.xz (Eigen and nlohmann/json headers);
#   2. configures and builds the trainer-only target (-DFVS_TRAINER_ONLY=ON, fvs_train_main:
#      LibTorch, Eigen and nlohmann headers only) against python3's torch
#      (torch.utils.cmake_prefix_path; else FVS_TORCH_PREFIX; else CMake's default search, as
#      Debian's LibTorch here);
#   3. trains the reference `fvs` variant (FVS_VARIANT) for MINUTES (default 5) of training
#      time on cuda when nvidia-smi sees a GPU, else on the CPU (FVS_DEVICE overrides),
#      validating against ulr on fox, middlebury_temple and monstree (--val_scene_list;
#      validation.csv has the network's and ulr's PSNR, SSIM and LPIPS per pass);
#   4. copies the log, validation.csv, model.json, model.safetensors (fp16) and, where it fits,
#      the newest checkpoint under $OUT (default gpu_out/), within what the device tool
#      brings back: at most 8 files, 16 MiB each, 64 MiB in all (one file kept for step 5);
#      a larger file comes back as xz-compressed parts NAME.xz.partNN (join:
#      cat NAME.xz.part* | xz -d > NAME);
#   5. the render benchmark of the trainer-only build (fvs_train_main --Train.benchmark 1,
#      src/fvs/train/render_benchmark.h) with the weights just trained: validation views
#      of the three validation scenes at 480x270 and 960x540, K = 1..8, fp32/bf16/fp16
#      (fp16 on CUDA only), within FVS_BENCH_S seconds; its table goes to the log and
#      $OUT/render_benchmark.csv;
#   6. when python3 has torch: scripts/gpu/torch_forward_bench.py, the same layer shapes in
#      PyTorch timed on the same device (random weights), within FVS_TORCH_BENCH_S
#      seconds; its table goes to the log only (the 8-file limit).
#
# Precision: on cuda the trainer runs with --Train.precision bf16 (autocast forward, fp32
# weights, optimiser and loss); on the CPU fp32. FVS_PRECISION overrides.
#
# Resume: files in gpu_resume/ (carried) are picked up. checkpoint-*.pt there is copied into
# the output folder and the trainer continues from it (optimiser state, step and the training
# minutes of all invocations included). Without one, model.safetensors there (or its .xz
# parts) starts the run from those weights (--Train.init_weights: a warm start with a fresh
# optimiser, not an exact resume). The reference `fvs` (33.7 M parameters) has a checkpoint
# of 405 MB (fp32 weights + Adam moments), which can neither come back through $OUT nor
# travel in the 64 MiB carry; its fp16 weights (67.5 MB) come back as ~59 MB of xz parts
# but do not travel back in beside gpu_data/ (33 MB) either. So `fvs` trains within one
# window only; smaller variants resume exactly.
#
# Environment: OUT, FVS_VARIANT (fvs), FVS_DEVICE (cuda|cpu), FVS_PRECISION (bf16 on cuda,
# else fp32), FVS_BENCH_S (100; 0: no render benchmark), FVS_BENCH_ARGS (extra benchmark
# flags, e.g. "--Train.bench_ks 1,5"), FVS_TORCH_BENCH_S (40; 0: none), FVS_TORCH_PREFIX,
# FVS_CXX_STANDARD (20 for torch >= 2.10, else 17), FVS_CMAKE_ARGS (extra configure flags),
# FVS_TOTAL_SECONDS (540: the whole script's budget; training stops early enough to validate,
# ship and benchmark inside it), FVS_VAL_RESERVE_S (120: seconds kept for the final
# validation), FVS_SHIP_S (60: kept for compressing the weights),
# FVS_JOBS (nproc), FVS_BUILD_DIR (build-gpu), FVS_RUN_DIR (build-gpu-run).
set -uo pipefail

START=$(date +%s)
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
cd "$ROOT"
MINUTES=${1:-5}
[[ $# -gt 0 ]] && shift
OUT=${OUT:-$ROOT/gpu_out}
mkdir -p "$OUT"
LOG="$OUT/run.log"
exec > >(tee -a "$LOG") 2>&1
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}

TOTAL=${FVS_TOTAL_SECONDS:-540}
VAL_RESERVE=${FVS_VAL_RESERVE_S:-120}
BENCH_S=${FVS_BENCH_S:-100}
TORCH_BENCH_S=${FVS_TORCH_BENCH_S:-40}
SHIP_S=${FVS_SHIP_S:-60}
VARIANT=${FVS_VARIANT:-fvs}
BUILD=${FVS_BUILD_DIR:-$ROOT/build-gpu}
RUN=${FVS_RUN_DIR:-$ROOT/build-gpu-run}
DATA=$ROOT/gpu_data
JOBS=${FVS_JOBS:-$(nproc)}
step() { echo "=== [$(( $(date +%s) - START ))s] $*"; }
die() { echo "FAILED: $*"; exit 1; }

step "host: $(uname -m), $(nproc) cores; $(date -u)"
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null ||
  echo "no nvidia-smi"
command -v nvcc >/dev/null && nvcc --version | tail -1
cmake --version | head -1

# 1. Data and headers.
[[ -f $DATA/packed.tar.xz ]] || die "gpu_data/packed.tar.xz missing: run scripts/gpu/pack_training_set.sh and carry gpu_data"
step "unpack the training set"
python3 - "$DATA" <<'EOF' || die "unpacking"
import os, sys, tarfile
d = sys.argv[1]
with tarfile.open(os.path.join(d, "packed.tar.xz")) as t:
    t.extractall(d)
EOF
du -sh "$DATA/packed"
VENDOR=$ROOT/build-gpu-vendor
EXTRA_PREFIX=""
EIGEN_ARGS=()
if [[ -f /usr/include/eigen3/Eigen/Core && -f /usr/include/nlohmann/json.hpp && -z ${FVS_FORCE_VENDOR:-} ]]; then
  echo "Eigen and nlohmann/json: the machine's own"
else
  [[ -f $DATA/vendor.tar.xz ]] || die "no Eigen/nlohmann headers here and gpu_data/vendor.tar.xz missing"
  mkdir -p "$VENDOR"
  python3 -c 'import sys,tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])' \
    "$DATA/vendor.tar.xz" "$VENDOR" || die "unpacking vendor.tar.xz"
  export CPATH="$VENDOR/include${CPATH:+:$CPATH}"
  EXTRA_PREFIX=";$VENDOR"
  EIGEN_ARGS=(-DEigen3_DIR="$VENDOR/share/eigen3/cmake")
  echo "Eigen and nlohmann/json: vendored ($VENDOR)"
fi

# 2. Configure and build fvs_train_main.
TORCH_PREFIX=$(python3 -c 'import torch; print(torch.utils.cmake_prefix_path)' 2>/dev/null || true)
TORCH_VERSION=$(python3 -c 'import torch; print(torch.__version__)' 2>/dev/null || true)
TORCH_PREFIX=${TORCH_PREFIX:-${FVS_TORCH_PREFIX:-}}
echo "torch: ${TORCH_VERSION:-(no python torch)} prefix: ${TORCH_PREFIX:-(CMake default search)}"
if [[ -n $TORCH_PREFIX && -n $TORCH_VERSION ]]; then
  TORCH_LIB=$(python3 -c 'import torch,os; print(os.path.join(os.path.dirname(torch.__file__),"lib"))')
  export LD_LIBRARY_PATH="$TORCH_LIB${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
if [[ -z ${FVS_CXX_STANDARD:-} ]]; then
  FVS_CXX_STANDARD=17
  if [[ -n $TORCH_VERSION ]] && python3 -c 'import sys; v=[int(x) for x in sys.argv[1].split("+")[0].split(".")[:2]]; sys.exit(0 if v >= [2,10] else 1)' "$TORCH_VERSION"; then
    FVS_CXX_STANDARD=20
  fi
fi
# --no-as-needed: the trainer references no libtorch_cuda symbol, and a linker that drops
# unreferenced libraries would leave LibTorch without its CUDA backend at run time.
GEN=()
command -v ninja >/dev/null && GEN=(-G Ninja)
step "configure (C++$FVS_CXX_STANDARD)"
export TORCH_CUDA_ARCH_LIST=${TORCH_CUDA_ARCH_LIST:-9.0}
# shellcheck disable=SC2086
cmake -S "$ROOT" -B "$BUILD" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DFVS_TRAINER_ONLY=ON -DFVS_WITH_GUI=OFF -DFVS_BUILD_TESTS=OFF -DFVS_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_STANDARD="$FVS_CXX_STANDARD" \
  -DCMAKE_EXE_LINKER_FLAGS="-Wl,--no-as-needed" \
  -DCMAKE_PREFIX_PATH="${TORCH_PREFIX}${EXTRA_PREFIX}" "${EIGEN_ARGS[@]}" \
  ${FVS_CMAKE_ARGS:-} >"$OUT/configure.log" 2>&1 ||
  { tail -40 "$OUT/configure.log"; die "configure"; }
grep -E "FVS CUDA|Torch|CUDA" "$OUT/configure.log" | head -8
step "build fvs_train_main (-j$JOBS)"
cmake --build "$BUILD" --target fvs_train_main -j "$JOBS" >"$OUT/build.log" 2>&1 ||
  { grep -m20 -B2 -A8 "error" "$OUT/build.log"; tail -20 "$OUT/build.log"; die "build"; }
rm -f "$OUT/configure.log" "$OUT/build.log"
TRAINER=$BUILD/bin/fvs_train_main
[[ -x $TRAINER ]] || die "no $TRAINER"

# 3. Train and validate.
M=$RUN/$VARIANT
mkdir -p "$M"
INIT=()
if compgen -G "gpu_resume/checkpoint-*.pt" >/dev/null; then
  cp -n gpu_resume/checkpoint-*.pt gpu_resume/*.csv gpu_resume/*.json "$M"/ 2>/dev/null
  echo "resume: $(ls "$M"/checkpoint-*.pt | tr '\n' ' ')"
elif compgen -G "gpu_resume/model.safetensors*" >/dev/null; then
  if [[ ! -f gpu_resume/model.safetensors ]]; then
    cat gpu_resume/model.safetensors.xz.part* | xz -dc >"$RUN/init.safetensors" 2>/dev/null ||
      python3 -c 'import lzma,sys,glob; sys.stdout.buffer.write(lzma.decompress(b"".join(open(f,"rb").read() for f in sorted(glob.glob("gpu_resume/model.safetensors.xz.part*")))))' >"$RUN/init.safetensors"
  else
    cp gpu_resume/model.safetensors "$RUN/init.safetensors"
  fi
  cp -n gpu_resume/validation.csv "$M"/ 2>/dev/null
  INIT=(--Train.init_weights "$RUN/init.safetensors")
  echo "warm start from gpu_resume/model.safetensors (no optimiser state)"
fi
if [[ -z ${FVS_DEVICE:-} ]]; then
  FVS_DEVICE=cpu
  nvidia-smi -L >/dev/null 2>&1 && FVS_DEVICE=cuda
fi
if [[ -z ${FVS_PRECISION:-} ]]; then
  FVS_PRECISION=fp32
  [[ $FVS_DEVICE == cuda ]] && FVS_PRECISION=bf16
fi
TORCH_BENCH=0
if (( TORCH_BENCH_S > 0 )) && python3 -c 'import torch' 2>/dev/null; then TORCH_BENCH=1; fi
# Kept after training: shipping, the render benchmark, the PyTorch timing.
POST=$(( SHIP_S + BENCH_S + TORCH_BENCH * TORCH_BENCH_S ))
NOW=$(date +%s)
LEFT=$(( START + TOTAL - NOW ))
TRAIN_S=$(( LEFT - VAL_RESERVE - POST - 30 ))
(( TRAIN_S >= 30 )) || die "only ${LEFT}s left after the build: raise FVS_TOTAL_SECONDS"
MAXMIN=$(python3 -c "print(min($MINUTES, $TRAIN_S/60))")
HARD_STOP=$(( LEFT - POST - 30 ))
step "train $VARIANT on $FVS_DEVICE in $FVS_PRECISION: $MAXMIN min of training (asked $MINUTES), hard stop in ${HARD_STOP}s"
# Training time counts over invocations (kept in the checkpoint): a resumed run's limit is
# the time recorded in the model.json that came back with the checkpoint plus this run's.
TOTAL_MIN=$MAXMIN
if compgen -G "$M/checkpoint-*.pt" >/dev/null; then
  TOTAL_MIN=$(python3 - "$M" "$MAXMIN" <<'EOF'
import json, os, sys
m, add = sys.argv[1], float(sys.argv[2])
done = 0.0
try:
    done = 60 * float(json.load(open(os.path.join(m, "model.json"))).get("hours", 0))
except Exception:
    pass
print(done + add)
EOF
)
fi
timeout -s INT -k 20 "$HARD_STOP" "$TRAINER" \
  --scene_list "$DATA/train.txt" --val_scene_list "$DATA/val.txt" \
  --output_path "$M" --lpips_path "$DATA/lpips_alex.safetensors" \
  --Train.variant "$VARIANT" --Train.device "$FVS_DEVICE" --Train.precision "$FVS_PRECISION" \
  --Train.max_steps 1000000 --Train.max_train_minutes "$TOTAL_MIN" \
  --Train.fp16_weights 1 --Train.checkpoint_minutes 2 --Train.log_every 20 \
  "${INIT[@]}" "$@"
RC=$?
step "trainer exit $RC"
[[ -f $M/validation.csv ]] && tail -8 "$M/validation.csv"

# 4. Bring back what fits: 8 files, 16 MiB each, 64 MiB in all (run.log is one of them, and
# one is kept for the benchmark's CSV).
step "ship to $OUT"
KEEP_FILES=0
(( BENCH_S > 0 )) && KEEP_FILES=1
python3 - "$M" "$OUT" "$KEEP_FILES" <<'EOF'
import glob, lzma, os, shutil, sys
m, out = sys.argv[1], sys.argv[2]
FILE, TOTAL, NFILES = 16 * 2**20 - 4096, 63 * 2**20 - 2**20 * int(sys.argv[3]), 8 - int(sys.argv[3])
used = [os.path.getsize(os.path.join(out, f)) + 2 * 2**20 for f in os.listdir(out)]  # log grows
count, size = len(used), sum(used)
def put(src, name):
    global count, size
    raw = os.path.getsize(src)
    # xz takes weights to no less than about 85 %: skip early what cannot fit (a 400 MB
    # checkpoint would take minutes to compress for nothing).
    if size + 0.8 * raw > TOTAL or count + max(1, int(0.8 * raw) // FILE + 1) > NFILES:
        print("does not fit, left behind: %s (%d bytes)" % (name, raw))
        return
    data = open(src, "rb").read()
    if len(data) > FILE:
        data = lzma.compress(data, preset=6)
        parts = [data[i:i + FILE] for i in range(0, len(data), FILE)]
        names = ["%s.xz.part%02d" % (name, i) for i in range(len(parts))]
    else:
        parts, names = [data], [name]
    if count + len(parts) > NFILES or size + len(data) > TOTAL:
        print("does not fit, left behind: %s (%d bytes, %d bytes as sent)" %
              (name, os.path.getsize(src), len(data)))
        return
    for p, n in zip(parts, names):
        open(os.path.join(out, n), "wb").write(p)
    count += len(parts); size += len(data)
    print("brought back: %s (%d bytes) as %s" % (name, os.path.getsize(src), " ".join(names)))
for name in ["validation.csv", "model.json", "model.safetensors"]:
    if os.path.isfile(os.path.join(m, name)):
        put(os.path.join(m, name), name)
cks = sorted(glob.glob(os.path.join(m, "checkpoint-*.pt")),
             key=lambda f: int(f.rsplit("-", 1)[1][:-3]))
if cks:
    put(cks[-1], os.path.basename(cks[-1]))
EOF

# 5. The render benchmark (trainer-only build): the weights just trained, else a fresh
# network (timing only; the CSV's PSNR then means nothing).
if (( BENCH_S > 0 )); then
  WEIGHTS=()
  [[ -f $M/model.safetensors ]] && WEIGHTS=(--Train.init_weights "$M/model.safetensors")
  NOW=$(date +%s)
  B=$(( START + TOTAL - NOW - TORCH_BENCH * TORCH_BENCH_S - 10 ))
  (( B > BENCH_S )) && B=$BENCH_S
  if (( B >= 30 )); then
    step "render benchmark on $FVS_DEVICE: ${B}s (grid bound $(( B - 25 ))s)"
    # shellcheck disable=SC2086
    timeout -s INT -k 10 "$B" "$TRAINER" \
      --scene_list "$DATA/val.txt" --val_scene_list "$DATA/val.txt" \
      --output_path "$RUN/bench" --Train.benchmark 1 --Train.variant "$VARIANT" \
      --Train.device "$FVS_DEVICE" --Train.bench_seconds $(( B - 25 )) "${WEIGHTS[@]}" \
      ${FVS_BENCH_ARGS:-}
    step "render benchmark exit $?"
    cp "$RUN/bench/render_benchmark.csv" "$OUT/" 2>/dev/null || echo "no render_benchmark.csv"
  else
    echo "render benchmark skipped: ${B}s left"
  fi
fi

# 6. The same layer shapes in PyTorch, on the same device (table in the log only).
if (( TORCH_BENCH )); then
  NOW=$(date +%s)
  B=$(( START + TOTAL - NOW - 10 ))
  (( B > TORCH_BENCH_S )) && B=$TORCH_BENCH_S
  if (( B >= 15 )); then
    CARD=()
    [[ -f $M/model.json ]] && CARD=(--config "$M/model.json")
    step "PyTorch forward of the same layers: ${B}s"
    timeout -k 5 "$B" python3 "$ROOT/scripts/gpu/torch_forward_bench.py" "${CARD[@]}" \
      --device "$FVS_DEVICE" --seconds $(( B - 15 ))
    step "PyTorch forward exit $?"
  fi
else
  echo "PyTorch forward timing skipped: python3 has no torch (or FVS_TORCH_BENCH_S=0)"
fi
ls -l "$OUT"
step "done (trainer exit $RC)"
exit $RC
