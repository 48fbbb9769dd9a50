#!/usr/bin/env bash
# The whole pipeline on the embedded synthetic scene: photos -> COLMAP SfM -> stereo -> fusion
# -> Delaunay mesh -> novel views, written to demo_output/. Installs what is missing, builds
# into build/, and skips every stage whose outputs are current (a rerun takes seconds).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh

COLMAP="$PWD/build/bin/colmap"
OUT="${FVS_DEMO_OUTPUT:-demo_output}"
VIEWS="${FVS_DEMO_VIEWS:-16}"
# Stereo at 400 px keeps the CPU PatchMatch to a few minutes on 2 cores.
STEREO_SIZE="${FVS_DEMO_STEREO_SIZE:-400}"
export QT_QPA_PLATFORM=offscreen
mkdir -p "$OUT"
start=$(date +%s)

# 1. The photos: a generated textured room seen from a handheld-like path (ground truth kept
#    beside them for evaluation; the pipeline below sees only the images).
if [[ ! -f "$OUT/synthetic/ground_truth/scene.json" ]]; then
  "$COLMAP" view_synthesis_synthetic --output_path "$OUT/synthetic" \
    --SyntheticScene.num_views "$VIEWS"
fi

# 2. Photos -> ready scene (SfM, undistortion, stereo, fusion, mesh, source depths). The last
#    photo is held out: registered, but kept out of the geometry, so it can be rendered and
#    compared with the truth.
last=$(ls "$OUT/synthetic/images" | sort | tail -n 1)
"$COLMAP" view_synthesis_prepare --image_path "$OUT/synthetic/images" \
  --workspace_path "$OUT/workspace" --holdout_images "$last" \
  --Stereo.max_image_size "$STEREO_SIZE"

# 3. Novel views between the registered cameras with the classical ULR baseline (no weights
#    needed), and with the network when shipped weights exist.
"$COLMAP" view_synthesis --workspace_path "$OUT/workspace" --output_path "$OUT/novel_views_ulr" \
  --method ulr --interpolate 4
if ls models/*.safetensors >/dev/null 2>&1; then
  # models/<variant>.safetensors: the method is the variant the file is named for.
  model=$(ls models/*.safetensors | head -n 1)
  variant=$(basename "$model" .safetensors)
  "$COLMAP" view_synthesis --workspace_path "$OUT/workspace" \
    --output_path "$OUT/novel_views_$variant" --method "$variant" --model_path "$model" \
    --interpolate 4
fi

# 4. A short fly-through: a Ceres-smoothed path through five registered cameras, rendered
#    with temporally stable sources, encoded to H.264 when ffmpeg can be installed (the
#    frames and frame_report.csv are written either way).
scripts/install_deps.sh ffmpeg || echo "demo: ffmpeg could not be installed; the fly-through stays frames only"
mapfile -t names < <(ls "$OUT/workspace/images" | sort)
step=$(( (${#names[@]} - 1) / 4 )); (( step < 1 )) && step=1
keys=""
for (( i = 0; i < ${#names[@]}; i += step )); do keys+="${keys:+,}${names[$i]}"; done
"$COLMAP" view_synthesis_path --workspace_path "$OUT/workspace" \
  --output_path "$OUT/flythrough/camera_path.json" --keyframes "$keys" \
  --fps 12 --seconds_per_keyframe 1.5 --images_txt "$OUT/flythrough/model/images.txt"
"$COLMAP" view_synthesis --workspace_path "$OUT/workspace" --method ulr \
  --camera_path "$OUT/flythrough/camera_path.json" --output_path "$OUT/flythrough/frames" \
  --stable_sources 1 --video "$OUT/flythrough/flythrough.mp4"

echo
echo "demo: done in $(( $(date +%s) - start )) s"
echo "  photos:       $OUT/synthetic/images"
echo "  workspace:    $OUT/workspace (sparse/, stereo/, fused.ply, meshed-delaunay.ply)"
echo "  novel views:  $OUT/novel_views_ulr"
echo "  fly-through:  $OUT/flythrough (camera_path.json, frames/, frame_report.csv, flythrough.mp4 with ffmpeg)"
