#!/usr/bin/env bash
# Behaviour and speed of two builds side by side (issue 19 item 8: the command layer moved
# into controllers/ and one option parser must change neither outputs nor timings):
#   benchmark/refactor_ab.sh A_COLMAP B_COLMAP [OUT]
# On the demo's generated scene: prepares the workspace with each binary (A then B, timed);
# from A's SfM, finishes stereo, fusion, meshing and the depth cache with each binary and
# compares every file (cmp); then renders A's workspace with each binary, alternating
# A B A B, and compares the frames. Flags that select behaviour
# changed on purpose between the two builds go in FVS_AB_PREPARE_A / FVS_AB_PREPARE_B (for
# example B's --DelaunayMeshing.sparse_min_track_length 0, the mesher input A had), so that
# only the refactor is compared. Prints seconds per stage and binary, and the machine.
set -euo pipefail
A="$(realpath "$1")"
B="$(realpath "$2")"
OUT="${3:-/tmp/refactor_ab}"
VIEWS="${FVS_AB_VIEWS:-16}"
read -r -a EXTRA_A <<< "${FVS_AB_PREPARE_A:-}"
read -r -a EXTRA_B <<< "${FVS_AB_PREPARE_B:-}"
export QT_QPA_PLATFORM=offscreen FVS_QUIET=1
rm -rf "$OUT"
mkdir -p "$OUT"

seconds() {  # seconds LOG COMMAND...: runs it, appends its wall time to LOG
  local log=$1
  shift
  local start end
  start=$(date +%s.%N)
  "$@" > "$OUT/last.log" 2>&1 || { cat "$OUT/last.log"; exit 1; }
  end=$(date +%s.%N)
  echo "$end - $start" | bc >> "$log"
}

"$B" view_synthesis_synthetic --output_path "$OUT/synthetic" \
  --SyntheticScene.num_views "$VIEWS" > /dev/null
last=$(ls "$OUT/synthetic/images" | sort | tail -n 1)
# prepare_both TIMES_STEM WORKSPACE_PREFIX: view_synthesis_prepare with A into
# OUT/<prefix>a, then with B into OUT/<prefix>b, each with its extra flags, timed.
prepare_both() {
  local side bin extra
  for side in a b; do
    bin=$A extra=("${EXTRA_A[@]}")
    [[ $side == b ]] && bin=$B extra=("${EXTRA_B[@]}")
    seconds "$OUT/$1_$side.txt" "$bin" view_synthesis_prepare \
      --image_path "$OUT/synthetic/images" --workspace_path "$OUT/$2$side" \
      --holdout_images "$last" --Stereo.max_image_size 400 "${extra[@]}"
  done
}

prepare_both prepare ""

# COLMAP's SfM differs from run to run of the same binary (threaded matching and mapping),
# so the outputs are compared from one SfM: A's workspace with the stages after
# undistortion forgotten, finished by each binary.
python3 - "$OUT/a" "$OUT/sa" "$OUT/sb" <<'PY'
import json, shutil, sys
src = sys.argv[1]
for dst in sys.argv[2:]:
    shutil.copytree(src, dst, symlinks=True)
    manifest = json.load(open(dst + "/fvs/manifest.json"))
    for stage in ("stereo", "fusion", "meshing", "depth_cache"):
        for output in manifest["stages"].pop(stage)["outputs"]:
            shutil.rmtree(dst + "/" + output, ignore_errors=True)
            try:
                __import__("os").remove(dst + "/" + output)
            except OSError:
                pass
    json.dump(manifest, open(dst + "/fvs/manifest.json", "w"), indent=2)
PY
prepare_both stages s
same=0 differ=0
while IFS= read -r file; do
  case "$file" in *.log | */manifest.json) continue ;; esac
  if cmp -s "$OUT/sa/$file" "$OUT/sb/$file"; then
    same=$((same + 1))
  else
    differ=$((differ + 1))
    echo "prepare from one SfM: differs: $file"
  fi
done < <(cd "$OUT/sa" && find . -type f | sort)
echo "prepare from one SfM: $same files identical, $differ differ"

# COLMAP's fusion is not deterministic either (threaded), so the mesher is compared on one
# fused cloud (A's, from one SfM) too; FVS_AB_MESHER_B pins what changed on purpose.
read -r -a MESHER_B <<< "${FVS_AB_MESHER_B:-}"
seconds "$OUT/mesher_a.txt" "$A" view_synthesis_mesher --workspace_path "$OUT/sa" \
  --output_path "$OUT/mesh_a.ply"
seconds "$OUT/mesher_b.txt" "$B" view_synthesis_mesher --workspace_path "$OUT/sa" \
  --output_path "$OUT/mesh_b.ply" "${MESHER_B[@]}"
cmp -s "$OUT/mesh_a.ply" "$OUT/mesh_b.ply" && echo "mesher on one fused cloud: identical" ||
  echo "mesher on one fused cloud: DIFFERS"

# Renders of the same workspace (A's), alternating so that load changes hit both.
for round in 1 2; do
  for side in a b; do
    bin=$A
    [[ $side == b ]] && bin=$B
    rm -rf "$OUT/render_$side"
    seconds "$OUT/render_$side.txt" "$bin" view_synthesis --workspace_path "$OUT/a" \
      --output_path "$OUT/render_$side" --method ulr --interpolate 4
  done
done
frames=0 frames_differ=0
for f in "$OUT"/render_a/*.png; do
  frames=$((frames + 1))
  cmp -s "$f" "$OUT/render_b/$(basename "$f")" || frames_differ=$((frames_differ + 1))
done
echo "render: $frames frames, $frames_differ differ"

mean() { awk '{ s += $1; n++ } END { printf "%.2f", s / n }' "$1"; }
echo "seconds (mean of runs): prepare A $(mean "$OUT/prepare_a.txt") B $(mean "$OUT/prepare_b.txt");" \
  "stereo to depth cache A $(mean "$OUT/stages_a.txt") B $(mean "$OUT/stages_b.txt");" \
  "mesher A $(mean "$OUT/mesher_a.txt") B $(mean "$OUT/mesher_b.txt");" \
  "render A $(mean "$OUT/render_a.txt") B $(mean "$OUT/render_b.txt") (runs: $(paste -sd' ' "$OUT/render_a.txt") / $(paste -sd' ' "$OUT/render_b.txt"))"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%FT%TZ)"
