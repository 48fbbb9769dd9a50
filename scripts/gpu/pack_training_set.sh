#!/usr/bin/env bash
# Packs the training set for a GPU machine (issue 20, doc/training.md "On a GPU machine").
#
#   scripts/gpu/pack_training_set.sh [WS_ROOT] [OUT_DIR]
#
# WS_ROOT (default /work/fvs_training/ws) holds prepared workspaces, one folder per scene
# (`colmap view_synthesis_prepare`); they are packed, not re-prepared. Each one becomes
# OUT_DIR/packed/<scene>/scene.safetensors at quarter resolution
# (`colmap view_synthesis_pack --scale 0.25`, as the paper), and OUT_DIR (default gpu_data/,
# git-ignored) gets train.txt and val.txt with paths relative to OUT_DIR's parent (the
# repository root, where scripts/gpu/run.sh runs). Validation scenes: fox,
# middlebury_temple, monstree (FVS_VAL_SCENES overrides, space separated); every other
# workspace trains.
#
# What travels is OUT_DIR/packed.tar.xz (plus the lists and the LPIPS weights, copied to
# OUT_DIR/lpips_alex.safetensors when found): the device unpacks it with python3's tarfile
# (no xz binary needed). The script prints the sizes; all of OUT_DIR must stay within the
# 64 MiB carry limit together with the other carried paths (gpu_data/ is all of it here).
#
# Environment: COLMAP (default /work/main/build/bin/colmap, else `colmap` on PATH),
# FVS_PACK_SCALE (0.25), FVS_PACK_THREADS (2), FVS_LPIPS_WEIGHTS (default
# ../shared/weights/lpips_alex.safetensors of the repository root, then
# /work/shared/weights/lpips_alex.safetensors).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/../.." && pwd)
WS_ROOT=${1:-/work/fvs_training/ws}
OUT_DIR=${2:-$ROOT/gpu_data}
SCALE=${FVS_PACK_SCALE:-0.25}
THREADS=${FVS_PACK_THREADS:-2}
VAL_SCENES=${FVS_VAL_SCENES:-"fox middlebury_temple monstree"}
if [[ -z "${COLMAP:-}" ]]; then
  if [[ -x /work/main/build/bin/colmap ]]; then COLMAP=/work/main/build/bin/colmap
  else COLMAP=$(command -v colmap); fi
fi

STAGE=${FVS_PACK_STAGE:-$ROOT/build-gpu-pack}
mkdir -p "$OUT_DIR" "$STAGE"
OUT_DIR=$(cd "$OUT_DIR" && pwd)
rm -rf "$OUT_DIR/packed"
: >"$OUT_DIR/train.txt.tmp"
: >"$OUT_DIR/val.txt.tmp"
for ws in "$WS_ROOT"/*/; do
  scene=$(basename "$ws")
  [[ -d "$ws/fvs" || -f "$ws/.done" ]] || { echo "skip $scene (not prepared)"; continue; }
  out="$STAGE/$scene"
  if [[ -s "$out/scene.safetensors" && "$out/scene.safetensors" -nt "$ws" &&
        "$(cat "$out/.scale" 2>/dev/null)" == "$SCALE" ]]; then
    echo "keep $scene (packed at $SCALE)"
  else
    echo "pack $scene"
    "$COLMAP" view_synthesis_pack --workspace_path "$ws" --output_path "$out" \
      --scale "$SCALE" --num_threads "$THREADS" >"$out.log" 2>&1 ||
      { tail -20 "$out.log"; echo "FAILED: $scene"; exit 1; }
    echo "$SCALE" >"$out/.scale"
  fi
  if [[ " $VAL_SCENES " == *" $scene "* ]]; then
    echo "packed/$scene" >>"$OUT_DIR/val.txt.tmp"
  else
    echo "packed/$scene" >>"$OUT_DIR/train.txt.tmp"
  fi
done
mv "$OUT_DIR/train.txt.tmp" "$OUT_DIR/train.txt"
mv "$OUT_DIR/val.txt.tmp" "$OUT_DIR/val.txt"

# One compressed archive travels; the uncompressed folders stay here (ignored by run.sh's
# carry list). Python's tarfile so that the device needs no xz binary to unpack.
python3 - "$OUT_DIR" "$STAGE" <<'EOF'
import os, sys, tarfile
out, stage = sys.argv[1], sys.argv[2]
tmp = os.path.join(out, "packed.tar.xz.tmp")
with tarfile.open(tmp, "w:xz", preset=6) as tar:
    for scene in sorted(os.listdir(stage)):
        f = os.path.join(stage, scene, "scene.safetensors")
        if os.path.isfile(f):
            tar.add(f, arcname=os.path.join("packed", scene, "scene.safetensors"))
os.replace(tmp, os.path.join(out, "packed.tar.xz"))
EOF

LPIPS=${FVS_LPIPS_WEIGHTS:-}
for c in "$LPIPS" "$ROOT/../shared/weights/lpips_alex.safetensors" \
         /work/shared/weights/lpips_alex.safetensors; do
  if [[ -n "$c" && -f "$c" ]]; then install -m 644 "$c" "$OUT_DIR/lpips_alex.safetensors"; break; fi
done

# Header-only dependencies of the trainer-only build, which the device (no Debian packages)
# may lack: Eigen (with its CMake config, which finds the headers relative to itself) and
# nlohmann/json. run.sh unpacks them when the device has none of its own.
python3 - "$OUT_DIR" <<'EOF'
import os, sys, tarfile
out = sys.argv[1]
tmp = os.path.join(out, "vendor.tar.xz.tmp")
with tarfile.open(tmp, "w:xz", preset=6) as tar:
    for src, dst in [("/usr/include/eigen3", "include/eigen3"),
                     ("/usr/include/nlohmann", "include/nlohmann"),
                     ("/usr/share/eigen3/cmake", "share/eigen3/cmake")]:
        if not os.path.exists(src):
            sys.exit("missing " + src + " (apt-get install libeigen3-dev nlohmann-json3-dev)")
        tar.add(src, arcname=dst)
os.replace(tmp, os.path.join(out, "vendor.tar.xz"))
EOF

echo "train: $(wc -l <"$OUT_DIR/train.txt") scenes, val: $(wc -l <"$OUT_DIR/val.txt") scenes"
echo "packed (uncompressed): $(du -cb "$STAGE"/*/scene.safetensors | tail -1 | cut -f1) bytes"
echo "packed.tar.xz:         $(stat -c %s "$OUT_DIR/packed.tar.xz") bytes"
[[ -f "$OUT_DIR/lpips_alex.safetensors" ]] &&
  echo "lpips_alex.safetensors: $(stat -c %s "$OUT_DIR/lpips_alex.safetensors") bytes"
echo "vendor.tar.xz:          $(stat -c %s "$OUT_DIR/vendor.tar.xz") bytes"
echo "$OUT_DIR in all:        $(du -sb "$OUT_DIR" | cut -f1) bytes (carry limit 67108864 with the tree)"
