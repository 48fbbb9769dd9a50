#!/usr/bin/env bash
# Quality against minutes of per-scene fine-tuning (view_synthesis_finetune), on views held
# out of the geometry at prepare (view_synthesis_eval --protocol holdout; the workspaces
# must have been prepared with --holdout_images):
#   benchmark/finetune_sweep.sh GENERIC.safetensors OUT WORKSPACE [WORKSPACE ...]
# For each workspace: ulr, the generic weights, then the fine-tuned model after each
# budget of FVS_SWEEP_MINUTES (default "1 3 10"; each run goes on from the last, so the
# model at 10 minutes is the one a single --minutes 10 run makes, in its wall time). Starts
# afresh: removes W/fvs/finetune and W/fvs/finetuned first. Writes OUT/<scene>/<config>/
# (the eval folders) and OUT/sweep.csv; prints the table and the machine.
set -euo pipefail
cd "$(dirname "$0")/.."
GENERIC="$(realpath "${1:?usage: benchmark/finetune_sweep.sh GENERIC.safetensors OUT WORKSPACE...}")"
OUT="$(realpath -m "${2:?output folder}")"
shift 2
COLMAP="${COLMAP:-$PWD/build/bin/colmap}"
LPIPS="${FVS_LPIPS_PATH:-$(realpath -m ../shared/weights/lpips_alex.safetensors)}"
[[ -f "$LPIPS" ]] || { echo "finetune_sweep: $LPIPS: no LPIPS weights" >&2; exit 2; }
MINUTES="${FVS_SWEEP_MINUTES:-1 3 10}"
VARIANT="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["variant"])' \
  "${GENERIC%.safetensors}.json" 2>/dev/null || echo fvs_agg)"
export OMP_WAIT_POLICY=PASSIVE
mkdir -p "$OUT"
{ date -u; uptime; echo "nproc $(nproc), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"; } \
  > "$OUT/machine.txt"
echo "scene,config,minutes,steps,views,psnr,ssim,lpips,seconds_per_view" > "$OUT/sweep.csv"

evaluate() {  # scene ws config minutes steps [eval options]
  local scene=$1 ws=$2 config=$3 minutes=$4 steps=$5; shift 5
  "$COLMAP" view_synthesis_eval --workspace_path "$ws" --output_path "$OUT/$scene/$config" \
    --protocol holdout --lpips_path "$LPIPS" "$@" > "$OUT/$scene/$config.log" 2>&1
  python3 - "$OUT/$scene/$config/summary.csv" "$scene,$config,$minutes,$steps" \
    >> "$OUT/sweep.csv" <<'EOF'
import csv, sys
row = next(csv.DictReader(open(sys.argv[1])))
print(f"{sys.argv[2]},{row['views_ok']},{row['psnr']},{row['ssim']},{row['lpips']},{row['seconds_per_view']}")
EOF
}

for ws in "$@"; do
  scene="$(basename "$ws")"
  mkdir -p "$OUT/$scene"
  rm -rf "$ws/fvs/finetune" "$ws/fvs/finetuned"
  evaluate "$scene" "$ws" ulr 0 0 --method ulr
  evaluate "$scene" "$ws" generic 0 0 --method "$VARIANT" --model_path "$GENERIC"
  for m in $MINUTES; do
    "$COLMAP" view_synthesis_finetune --workspace_path "$ws" --minutes "$m" \
      --method "$VARIANT" --model_path "$GENERIC" --lpips_path "$LPIPS" \
      > "$OUT/$scene/finetune_$m.log" 2>&1
    steps="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["finetune"]["steps"])' \
      "$ws/fvs/finetuned/$VARIANT.json")"
    evaluate "$scene" "$ws" "finetuned_${m}min" "$m" "$steps" --method "$VARIANT"
  done
done
cat "$OUT/machine.txt"
column -s, -t < "$OUT/sweep.csv"
