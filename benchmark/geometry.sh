#!/usr/bin/env bash
# The geometry benchmark (issue 39, doc/real_scenes.md): prepares scenes of
# ../shared/datasets with every 5th photo held out of the geometry, and a generated scene
# with exact depth, then reports per scene the coverage of the stereo maps and of the mesh
# (geometry_benchmark), the depth error where the truth is known (Middlebury: camera error
# against the published calibration), `ulr` PSNR / SSIM / LPIPS
# on the held-out views with seconds per view, and seconds per stage (W/fvs/manifest.json).
#
#   benchmark/geometry.sh [SCENE[:STEP] ...]   # default: synthetic and every dataset scene
#   FVS_GEOMETRY_TAG=after FVS_GEOMETRY_BASELINE=before benchmark/geometry.sh fox:2 ...
#
# SCENE is a folder of ../shared/datasets (every STEP-th photo, default 1), `synthetic` (the
# demo room) or `synthetic_plain` (the same room with textureless walls, floor, ceiling).
# Workspaces go to $FVS_GEOMETRY_WORK/<tag>/<scene> (default /tmp/fvs_geometry, tag
# `run`); a variant reuses the SfM of any other tag's workspace of the same photos, so only
# the dense stages run again. FVS_GEOMETRY_BASELINE names a tag whose workspaces the
# "newly covered" depth errors compare against; FVS_GEOMETRY_REUSE names a tag whose
# whole workspaces are copied first (a workspace prepared before a change: prepare reruns
# only the stages whose inputs changed, and the stage times say what that cost).
# FVS_GEOMETRY_PREPARE_ARGS are passed to
# view_synthesis_prepare (e.g. "--Stereo.max_image_size 400"); FVS_GEOMETRY_HEADROOM=1 adds
# the headroom tool's per-pixel and per-8x8 oracles beside `ulr` (slower). Results:
# <tag>/<scene>.geometry.json, <tag>/<scene>.eval/summary.csv, <tag>/table.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN="${FVS_GEOMETRY_BIN:-$PWD/${FVS_BUILD_DIR:-build}/bin}"  # a copy keeps a long run safe from rebuilds
COLMAP="$BIN/colmap"
DATASETS="$(realpath -m "${FVS_DATASETS:-../shared/datasets}")"
WORK="${FVS_GEOMETRY_WORK:-/tmp/fvs_geometry}"
TAG="${FVS_GEOMETRY_TAG:-run}"
BASELINE="${FVS_GEOMETRY_BASELINE:-}"
REUSE="${FVS_GEOMETRY_REUSE:-}"
read -r -a PREPARE_ARGS <<< "${FVS_GEOMETRY_PREPARE_ARGS:-}"
LPIPS="$(realpath -m "${FVS_LPIPS_PATH:-../shared/weights/lpips_alex.safetensors}")"
LPIPS_ARGS=()
[[ -f "$LPIPS" ]] && LPIPS_ARGS=(--lpips_path "$LPIPS")
[[ -x "$COLMAP" && -x "$BIN/geometry_benchmark" ]] || {
  echo "ERROR: $BIN has no colmap or geometry_benchmark: run scripts/build.sh" >&2; exit 2; }
SCENES=("$@")
if (( ${#SCENES[@]} == 0 )); then
  SCENES=(synthetic synthetic_plain)
  for d in "$DATASETS"/*/; do [[ -d $d/images ]] && SCENES+=("$(basename "$d")"); done
fi
OUT="$WORK/$TAG"
mkdir -p "$OUT" "$WORK/images"
{ echo "date: $(date -u +%FT%TZ)  tag: $TAG  prepare args: ${PREPARE_ARGS[*]:-(defaults)}"
  echo "cpu: $(nproc) x$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
  echo "load: $(cut -d' ' -f1-3 /proc/loadavg)  commit: $(git rev-parse --short HEAD)$(git diff --quiet || echo +changes)"
} | tee "$OUT/machine.txt"

# Every STEP-th photo of a dataset scene, linked into $WORK/images/<scene>_<step>; the
# holdout list is every 5th of those.
link_photos() {
  local scene=$1 step=$2 dir=$WORK/images/$1_$2 i=0 j=0
  if [[ ! -d $dir ]]; then
    mkdir -p "$dir.tmp"
    for f in $(ls "$DATASETS/$scene/images" | sort); do
      (( i % step == 0 )) && ln -sf "$DATASETS/$scene/images/$f" "$dir.tmp/$f"
      i=$((i + 1))
    done
    mv "$dir.tmp" "$dir"
  fi
  : > "$dir.holdout.txt"
  for f in $(ls "$dir" | sort); do
    (( j % 5 == 0 )) && echo "$f" >> "$dir.holdout.txt"
    j=$((j + 1))
  done
}

# The SfM of another tag's workspace of the same photos (database, model, report and the
# manifest, whose paths are relative): only the dense stages run again.
borrow_sfm() {
  local name=$1 ws=$2 donor
  [[ -d $ws/sfm ]] && return 0
  for donor in "$WORK"/*/"$name"; do
    [[ $donor != "$ws" && -f $donor/.done ]] || continue
    mkdir -p "$ws/fvs"
    cp -a "$donor/database.db" "$donor/sfm" "$ws/"
    cp -a "$donor/fvs/registration.json" "$donor/fvs/manifest.json" "$ws/fvs/"
    echo "  SfM of $donor"
    return 0
  done
}

# The generated room with exact depth: its true cameras, our stereo, COLMAP's fusion and
# our mesher with prepare's defaults, stage by stage (prepare would re-estimate the
# cameras in another frame).
prepare_synthetic() {
  local ws=$1 truth=$2 plain=0
  [[ $truth == *plain* ]] && plain=1
  [[ -f $truth/ground_truth/scene.json ]] ||
    "$COLMAP" view_synthesis_synthetic --output_path "$truth" \
      --SyntheticScene.plain_walls $plain > /dev/null
  [[ -f $ws/.done ]] && return 0
  rm -rf "$ws" && mkdir -p "$ws/fvs"
  cp -a "$truth/images" "$truth/sparse" "$ws/"
  local t0=$EPOCHREALTIME t1 t2 t3
  "$COLMAP" view_synthesis_stereo --workspace_path "$ws" "${PREPARE_ARGS[@]/--Stereo./--PatchMatchStereo.}" > "$ws.log" 2>&1
  t1=$EPOCHREALTIME
  colmap stereo_fusion --workspace_path "$ws" --input_type geometric \
    --output_path "$ws/fused.ply" >> "$ws.log" 2>&1
  t2=$EPOCHREALTIME
  "$COLMAP" view_synthesis_mesher --workspace_path "$ws" >> "$ws.log" 2>&1
  t3=$EPOCHREALTIME
  "$COLMAP" view_synthesis_depth_cache --workspace_path "$ws" >> "$ws.log" 2>&1
  python3 - "$ws/fvs/stage_seconds.json" "$t0" "$t1" "$t2" "$t3" "$EPOCHREALTIME" <<'EOF'
import json, sys
t = [float(v) for v in sys.argv[2:]]
json.dump({"stereo": t[1] - t[0], "fusion": t[2] - t[1], "meshing": t[3] - t[2],
           "depth_cache": t[4] - t[3]}, open(sys.argv[1], "w"))
EOF
  touch "$ws/.done"
}

prepare_dataset() {
  local scene=$1 step=$2 ws=$3 photos=$WORK/images/$1_$2
  link_photos "$scene" "$step"
  [[ -f $ws/.done ]] && return 0
  if [[ -n $REUSE && -f $WORK/$REUSE/$(basename "$ws")/.done && ! -d $ws ]]; then
    cp -a "$WORK/$REUSE/$(basename "$ws")" "$ws" && rm -f "$ws/.done"
    echo "  a copy of $WORK/$REUSE/$(basename "$ws"): prepare reruns what changed"
  fi
  borrow_sfm "$(basename "$ws")" "$ws"
  local model=SIMPLE_RADIAL
  "$COLMAP" view_synthesis_prepare --image_path "$photos" --workspace_path "$ws" \
    --holdout_images "$photos.holdout.txt" "${PREPARE_ARGS[@]}" > "$ws.log" 2>&1 ||
    { echo "  prepare failed: $ws.log"; tail -3 "$ws.log"; return 1; }
  touch "$ws/.done"
}

for spec in "${SCENES[@]}"; do
  IFS=: read -r scene step <<< "$spec"
  step=${step:-1}
  name=$scene
  [[ $scene == synthetic* ]] || name=${scene}_$step
  ws="$OUT/$name"
  echo "== $name ($TAG)"
  if [[ $scene == synthetic* ]]; then
    prepare_synthetic "$ws" "$WORK/${scene}_truth"
    truth=(--truth_path "$WORK/${scene}_truth")
  else
    prepare_dataset "$scene" "$step" "$ws" || continue
    truth=()
    # The Middlebury scenes ship their published calibration as sparse/0.
    [[ $scene == middlebury_* && -d $DATASETS/$scene/sparse/0 ]] &&
      truth=(--reference_model "$DATASETS/$scene/sparse/0")
  fi
  base=()
  [[ -n $BASELINE && -f $WORK/$BASELINE/$name/.done ]] && base=(--baseline_path "$WORK/$BASELINE/$name")
  "$BIN/geometry_benchmark" --workspace_path "$ws" "${truth[@]}" "${base[@]}" \
    --output_path "$OUT/$name.geometry.json" | sed 's/^/  /'
  if [[ -s $ws/fvs/holdout.txt && ! -f $OUT/$name.eval/summary.csv ]]; then
    FVS_QUIET=1 "$COLMAP" view_synthesis_eval --workspace_path "$ws" --output_path "$OUT/$name.eval" \
      --method ulr --protocol holdout "${LPIPS_ARGS[@]}" > "$OUT/$name.eval.log" 2>&1 ||
      echo "  eval failed: $OUT/$name.eval.log"
  fi
  if [[ ${FVS_GEOMETRY_HEADROOM:-0} == 1 && -s $ws/fvs/holdout.txt && ! -f $OUT/$name.headroom/done ]]; then
    mkdir -p "$OUT/$name.headroom"
    # Half size, as the training set and doc/training.md's headroom tables.
    FVS_QUIET=1 "$COLMAP" view_synthesis_pack --workspace_path "$ws" --scale 0.5 \
      --output_path "$OUT/$name.headroom/packed" > "$OUT/$name.headroom/log" 2>&1 &&
    echo "$OUT/$name.headroom/packed" > "$OUT/$name.headroom/list.txt" &&
    "$BIN/fvs_headroom_main" --val_scene_list "$OUT/$name.headroom/list.txt" \
      "${LPIPS_ARGS[@]}" --holdout_targets 1 --methods ulr,oracle_pixel,oracle_patch8 \
      --quiet 1 --output_path "$OUT/$name.headroom" >> "$OUT/$name.headroom/log" 2>&1 &&
    touch "$OUT/$name.headroom/done" || echo "  headroom failed: $OUT/$name.headroom/log"
  fi
done

# The table: one row per scene of this tag.
python3 - "$OUT" "${SCENES[@]}" <<'EOF' | tee "$OUT/table.txt"
import csv, json, os, sys
out = sys.argv[1]
print("%-20s %6s %6s %6s %6s | %6s %6s %6s %5s | %s" % ("scene", "photo", "geom", "mesh",
      "least", "PSNR", "SSIM", "LPIPS", "s/vw", "seconds per stage / truth"))
for spec in sys.argv[2:]:
    scene, _, step = spec.partition(":")
    name = scene if scene.startswith("synthetic") else "%s_%s" % (scene, step or "1")
    path = os.path.join(out, name + ".geometry.json")
    if not os.path.exists(path):
        print("%-20s (not prepared)" % name); continue
    g = json.load(open(path))
    row = "%-20s %5.1f%% %5.1f%% %5.1f%% %5.1f%%" % (name, 100 * g["photometric"]["mean"],
          100 * g["geometric"]["mean"], 100 * g["mesh"]["mean"], 100 * g["mesh"]["least"])
    summary = os.path.join(out, name + ".eval", "summary.csv")
    if os.path.exists(summary):
        r = next(csv.DictReader(open(summary)))
        row += " | %6.2f %6.4f %6.4f %5.2f" % (float(r["psnr"]), float(r["ssim"]),
               float(r["lpips"] or "nan"), float(r["seconds_per_view"]))
    else:
        row += " | %6s %6s %6s %5s" % ("-", "-", "-", "-")
    ws = os.path.join(out, name)
    stages = {}
    manifest = os.path.join(ws, "fvs", "manifest.json")
    seconds = os.path.join(ws, "fvs", "stage_seconds.json")
    if os.path.exists(seconds):
        stages = json.load(open(seconds))
    elif os.path.exists(manifest):
        m = json.load(open(manifest))
        for k, v in (m.get("stages") or m).items():
            if isinstance(v, dict) and "seconds" in v: stages[k] = v["seconds"]
    row += " | " + " ".join("%s %.0f" % (k, v) for k, v in stages.items())
    for key in ("geometric_error", "mesh_error", "geometric_error_new", "mesh_error_new"):
        e = g.get(key)
        if e and e.get("pixels"):
            row += " | %s %.1f%%<1%% %.1f%%<5%% med %.4f" % (key, 100 * e["within_1pct"],
                   100 * e["within_5pct"], e["median_rel_error"])
    print(row)
    csv_path = os.path.join(out, name + ".headroom", "headroom.csv")
    if os.path.exists(csv_path):  # half size, the held-out views, K = 5
        print("    headroom (half size): " + " | ".join("%s %.2f / %.4f / %.4f" % (
            r["method"], float(r["psnr"]), float(r["ssim"]), float(r["lpips"]))
            for r in csv.DictReader(open(csv_path)) if r["scene"] == "all"))
EOF
