#!/usr/bin/env bash
# Flicker beside PSNR: a generated scene (exact ground truth in the workspace's own frame,
# exact mesh as the proxy), a smoothed fly-through from view_synthesis_path, its ground
# truth from view_synthesis_synthetic --camera_path, and the video rendered with each
# temporal setting. Prints flicker (8-bit levels), PSNR against the ground truth, source
# changes and time per frame, and the machine.
#
#   benchmark/video_stability.sh [WORK_DIR]      (default /tmp/fvs_video_stability)
#   FVS_VIDEO_METHODS="ulr nearest" FVS_VIDEO_SIZE="480 360" benchmark/video_stability.sh
set -euo pipefail
cd "$(dirname "$0")/.."
COLMAP="$PWD/${FVS_BUILD_DIR:-build}/bin/colmap"
WORK="${1:-/tmp/fvs_video_stability}"
read -r W H <<< "${FVS_VIDEO_SIZE:-320 240}"
METHODS="${FVS_VIDEO_METHODS:-ulr nearest}"
SCENE=(--SyntheticScene.num_views 30 --SyntheticScene.width "$W" --SyntheticScene.height "$H"
       --SyntheticScene.seed 3)
export FVS_QUIET=1
mkdir -p "$WORK"
[[ -f "$WORK/ws/ground_truth/scene.json" ]] ||
  "$COLMAP" view_synthesis_synthetic --output_path "$WORK/ws" "${SCENE[@]}" \
    --SyntheticScene.write_proxy_mesh 1 > /dev/null
# Keyframes every 6th view; the path holds out nothing, the frames lie between the views.
keys=$(ls "$WORK/ws/images" | awk 'NR % 6 == 2' | paste -sd,)
"$COLMAP" view_synthesis_path --workspace_path "$WORK/ws" --output_path "$WORK/path.json" \
  --keyframes "$keys" --fps 12 --seconds_per_keyframe 1 > /dev/null
"$COLMAP" view_synthesis_synthetic --output_path "$WORK/gt" "${SCENE[@]}" \
  --camera_path "$WORK/path.json" > /dev/null

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1 /proc/loadavg)"
echo "scene: generated (seed 3), ${W}x${H}, 30 views, path of $(grep -c camera_to_world "$WORK/path.json") frames, exact mesh"
printf "%-8s %-34s %8s %8s %9s %9s\n" method setting flicker PSNR changes ms/frame
for method in $METHODS; do
  for setting in "each frame alone|" "--stable_sources 1|--stable_sources 1" \
                 "+ --temporal_blend 0.3|--stable_sources 1 --temporal_blend 0.3"; do
    label=${setting%%|*}; args=${setting#*|}
    out="$WORK/out_${method}_$(echo "$label" | tr -c 'a-z0-9' _)"
    # shellcheck disable=SC2086
    "$COLMAP" view_synthesis --workspace_path "$WORK/ws" --camera_path "$WORK/path.json" \
      --output_path "$out" --method "$method" --ground_truth_path "$WORK/gt" \
      --overwrite 1 $args > /dev/null
    python3 - "$out/frame_report.json" "$method" "$label" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print("%-8s %-34s %8.3f %8.2f %9.2f %9.0f" % (sys.argv[2], sys.argv[3],
      r["mean_flicker_levels"], r["mean_psnr"], r["mean_source_changes"],
      1000 * r["mean_seconds_per_frame"]))
PY
  done
done
