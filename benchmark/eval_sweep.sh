#!/usr/bin/env bash
# Error against run time: `colmap view_synthesis_eval --sweep 1` on the demo scene and on a
# real scene of ../shared/datasets, with the Pareto tables and plots the doc shows
# (doc/evaluation.md). Every number comes with its time and the machine (machine.txt).
#
#   benchmark/eval_sweep.sh                  # both scenes
#   FVS_BUILD_DIR=build-train benchmark/eval_sweep.sh
#   FVS_EVAL_MODELS=a.safetensors,b.safetensors benchmark/eval_sweep.sh   # + network variants
#   FVS_EVAL_PRECISIONS=fp32,bf16 ...        # + the networks in bf16
#
# Needs: the demo workspace (scripts/demo.sh makes demo_output/workspace); for the real
# scene the photos at $FVS_DATASETS/sceaux_castle/images (prepared here into
# $FVS_EVAL_WORK/sceaux_ws, a few CPU minutes, with two photos held out of the geometry).
set -euo pipefail
cd "$(dirname "$0")/.."

COLMAP="$PWD/${FVS_BUILD_DIR:-build}/bin/colmap"
OUT="${FVS_EVAL_OUTPUT:-demo_output/eval}"
WORK="${FVS_EVAL_WORK:-/tmp/fvs_eval_work}"
DATASETS="${FVS_DATASETS:-../shared/datasets}"
MODELS="${FVS_EVAL_MODELS:-$(ls models/*.safetensors 2>/dev/null | paste -sd, || true)}"
SCALES="${FVS_EVAL_SCALES:-1,0.5,0.25}"
KS="${FVS_EVAL_KS:-1,2,3,4,5,6,7,8}"
PRECISIONS="${FVS_EVAL_PRECISIONS:-fp32}"  # fp32,bf16 (CPU or CUDA), fp16 (CUDA)
export QT_QPA_PLATFORM=offscreen
mkdir -p "$OUT" "$WORK"

sweep() {  # sweep NAME WORKSPACE PROTOCOL_ARGS...
  local name="$1" ws="$2"
  shift 2
  echo "== $name: $ws"
  "$COLMAP" view_synthesis_eval --workspace_path "$ws" --output_path "$OUT/$name" "$@" \
    --sweep 1 --sweep_num_sources "$KS" --sweep_scales "$SCALES" \
    --sweep_precisions "$PRECISIONS" \
    ${MODELS:+--sweep_model_paths "$MODELS"} --method ulr --num_sources 5
}

# 1. The demo scene (16 generated photos, 640x480; frame_0015 held out of the geometry):
#    every third image left out in turn, which includes the true holdout.
if [[ -f demo_output/workspace/meshed-delaunay.ply ]]; then
  sweep demo demo_output/workspace --protocol leave_one_out --every 3
else
  echo "no demo workspace (run scripts/demo.sh first): skipping the demo scene"
fi

# 2. sceaux_castle (11 photos, 800x601): two photos held out of SfM's dense geometry.
if [[ -d "$DATASETS/sceaux_castle/images" ]]; then
  "$COLMAP" view_synthesis_prepare --image_path "$DATASETS/sceaux_castle/images" \
    --workspace_path "$WORK/sceaux_ws" --Stereo.max_image_size 400 \
    --holdout_images 100_7103.jpg,100_7107.jpg
  sweep sceaux_castle "$WORK/sceaux_ws" --protocol holdout
else
  echo "no $DATASETS/sceaux_castle: skipping the real scene"
fi
echo "reports: $OUT/*/results.md, plots: $OUT/*/error_vs_time.png"
