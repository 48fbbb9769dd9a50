#!/usr/bin/env bash
# The mesher's input, fused points only (COLMAP's) against fused + SfM points (ours,
# --DelaunayMeshing.sparse_min_track_length), on prepared workspaces: mesh coverage of the
# photos, meshing time, and `ulr` quality with its seconds per view (doc/real_scenes.md).
# Each workspace is re-meshed in a scratch copy (symbolic links to its photos, model,
# stereo and fused points); the workspace itself is not touched.
#
#   benchmark/mesher_sfm_points.sh WORKSPACE [WORKSPACE ...]
#   FVS_MESHER_VARIANTS="0:2 2:2 3:2 3:1" ...   # min track length : max error (px)
#
# Protocol: holdout where the workspace holds photos out of the geometry (the views to
# report), else leave-one-out on every 3rd photo (those photos are in the geometry: only
# for ranking variants). LPIPS when ../shared/weights has the weights.
set -euo pipefail
cd "$(dirname "$0")/.."
COLMAP="$PWD/${FVS_BUILD_DIR:-build}/bin/colmap"
WORK="${FVS_MESHER_WORK:-/tmp/fvs_mesher_sfm}"
VARIANTS="${FVS_MESHER_VARIANTS:-0:2 2:2}"
LPIPS="${FVS_LPIPS_PATH:-$(realpath -m ../shared/weights/lpips_alex.safetensors)}"
LPIPS_ARGS=()
[[ -f "$LPIPS" ]] && LPIPS_ARGS=(--lpips_path "$LPIPS")
(( $# > 0 )) || { echo "usage: $0 WORKSPACE [WORKSPACE ...]" >&2; exit 2; }
mkdir -p "$WORK"
{ echo "date: $(date -u +%FT%TZ)"; echo "cpu: $(nproc) x $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)";
  echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"; } | tee "$WORK/machine.txt"

printf "%-18s %-9s %9s %9s %8s %8s %8s %8s\n" scene variant coverage mesh_s PSNR SSIM LPIPS s/view
for ws in "$@"; do
  ws="$(realpath "$ws")"
  scene="$(basename "$ws")"
  protocol=(--protocol leave_one_out --every 3)
  [[ -s "$ws/fvs/holdout.txt" ]] && protocol=(--protocol holdout)
  for variant in $VARIANTS; do
    IFS=: read -r track error <<< "$variant"
    dst="$WORK/$variant/$scene"
    rm -rf "$dst" && mkdir -p "$dst/fvs"
    for entry in "$ws"/*; do
      case "$(basename "$entry")" in meshed-delaunay.ply | fvs) ;; *) ln -s "$entry" "$dst/" ;; esac
    done
    cp "$ws"/fvs/manifest.json "$ws"/fvs/holdout.txt "$dst/fvs/" 2>/dev/null || true
    start=$EPOCHREALTIME
    FVS_QUIET=1 "$COLMAP" view_synthesis_mesher --workspace_path "$dst" \
      --DelaunayMeshing.sparse_min_track_length "$track" \
      --DelaunayMeshing.sparse_max_error "$error" > "$dst/mesher.log"
    mesh_s=$(python3 -c "print($EPOCHREALTIME - $start)")
    FVS_QUIET=1 "$COLMAP" view_synthesis_depth_cache --workspace_path "$dst" > "$dst/depth.log" 2>&1
    FVS_QUIET=1 "$COLMAP" view_synthesis_eval --workspace_path "$dst" \
      --output_path "$dst/eval" --method ulr "${protocol[@]}" "${LPIPS_ARGS[@]}" > "$dst/eval.log"
    coverage=$(python3 -c 'import json,sys; print("%.1f%%" % (100 * json.load(open(sys.argv[1]))["mean"]))' \
      "$dst/fvs/depth/coverage.json")
    # summary.csv: method,K,scale,precision,views,failed,psnr,ssim,lpips,...,seconds
    python3 - "$dst/eval/summary.csv" "$scene" "$variant" "$coverage" "$mesh_s" <<'EOF'
import csv, sys
row = next(csv.DictReader(open(sys.argv[1])))
print("%-18s %-9s %9s %9.1f %8s %8s %8s %8s" % (sys.argv[2], sys.argv[3], sys.argv[4],
      float(sys.argv[5]), row["psnr"][:6], row["ssim"][:6], row["lpips"][:6],
      row["seconds_per_view"][:6]))
EOF
  done
done
