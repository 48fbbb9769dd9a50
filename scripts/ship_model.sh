#!/usr/bin/env bash
# Decides whether a trained model replaces the shipped one, by the bar of doc/training.md:
# on every validation workspace, through view_synthesis_eval --protocol holdout (views
# held out of the geometry at prepare, never trained or validated on), the candidate
#   - beats ulr by at least 0.5 dB PSNR and 0.02 LPIPS with SSIM not lower, and
#   - beats the model shipped now (mean PSNR not lower and mean LPIPS lower, or PSNR
#     higher and LPIPS not higher: the trainer's best-model rule).
# Only then are models/<variant>.safetensors and its card replaced; the card gets the
# held-out figures with seconds per view. Prints the table either way; exit 0 = shipped,
# 1 = not shipped (the reason printed), 2 = error.
#   scripts/ship_model.sh CANDIDATE.safetensors [WORKSPACE ...]
# Default workspaces: the validation scenes of scripts/train_fvs_agg_cpu.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
CANDIDATE="$(realpath "${1:?usage: scripts/ship_model.sh CANDIDATE.safetensors [WORKSPACE ...]}")"
shift
WORKSPACES=("$@")
if (( ${#WORKSPACES[@]} == 0 )); then
  WORKSPACES=(/work/fvs_training/ws/fox /work/fvs_training/ws/middlebury_temple
              /work/fvs_training/ws/monstree)
fi
COLMAP="${COLMAP:-$PWD/build/bin/colmap}"
LPIPS="${FVS_LPIPS_PATH:-$(realpath -m ../shared/weights/lpips_alex.safetensors)}"
[[ -f "$LPIPS" ]] || { echo "ship_model: $LPIPS: no LPIPS weights (the bar needs LPIPS)" >&2; exit 2; }
CARD="${CANDIDATE%.safetensors}.json"
[[ -f "$CARD" ]] || { echo "ship_model: $CARD: no card beside the candidate" >&2; exit 2; }
VARIANT="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["variant"])' "$CARD")"
SHIPPED="models/$VARIANT.safetensors"
OUT="${FVS_SHIP_DIR:-/tmp/fvs_ship}"
mkdir -p "$OUT"

# What a workspace renders from: its mesh, cameras, holdout list and photos. Results are
# kept under it, so a workspace re-meshed or re-prepared never reuses them.
workspace_key() {
  { cat "$1/meshed-delaunay.ply" "$1"/sparse/*.bin "$1/fvs/holdout.txt" 2>/dev/null
    (cd "$1/images" && ls -l --time-style=+%s); } | sha256sum | cut -c1-12
}

# eval NAME WORKSPACE FOLDER [view_synthesis_eval options]: OUT/FOLDER/NAME/summary.csv
# (reused when there: results are keyed by the workspace's content in FOLDER and by the
# weights' hash in NAME).
evaluate() {
  local name=$1 ws=$2 dir="$OUT/$3/$1"; shift 3
  [[ -f "$dir/summary.csv" ]] && return 0
  # Weights are always named (--model_path), so a scene's fine-tuned ones never stand in.
  nice -n "${FVS_NICE:-0}" env OMP_WAIT_POLICY=PASSIVE "$COLMAP" view_synthesis_eval \
    --workspace_path "$ws" --output_path "$dir" --protocol holdout --lpips_path "$LPIPS" \
    "$@" > "$dir.log" 2>&1 || { echo "ship_model: evaluation failed: $dir.log" >&2; exit 2; }
}

hash_of() { sha256sum "$1" | cut -c1-16; }
FOLDERS=()  # OUT/<scene>-<workspace key>, one per workspace
for ws in "${WORKSPACES[@]}"; do
  folder="$(basename "$ws")-$(workspace_key "$ws")"
  FOLDERS+=("$folder")
  mkdir -p "$OUT/$folder"
  evaluate ulr "$ws" "$folder" --method ulr
  evaluate "candidate-$(hash_of "$CANDIDATE")" "$ws" "$folder" --method "$VARIANT" \
    --model_path "$CANDIDATE"
  if [[ -f "$SHIPPED" ]]; then
    evaluate "shipped-$(hash_of "$SHIPPED")" "$ws" "$folder" --method "$VARIANT" \
      --model_path "$SHIPPED"
  fi
done

python3 - "$OUT" "$CANDIDATE" "$CARD" "$SHIPPED" "$(hash_of "$CANDIDATE")" \
  "$([[ -f "$SHIPPED" ]] && hash_of "$SHIPPED")" "${FOLDERS[@]}" <<'EOF'
import csv, json, os, shutil, sys
out, candidate, card_path, shipped, cand_hash, shipped_hash = sys.argv[1:7]
keyed = sys.argv[7:]  # <scene>-<workspace key>: the folders of OUT

def summary(folder, name):
    with open(os.path.join(out, folder, name, "summary.csv")) as f:
        row = next(csv.DictReader(f))
    return {k: float(row[k]) for k in ("psnr", "ssim", "lpips", "seconds_per_view", "views_ok")}

rows, failures = [], []
for folder in keyed:
    scene = folder.rsplit("-", 1)[0]
    u, c = summary(folder, "ulr"), summary(folder, "candidate-" + cand_hash)
    s = summary(folder, "shipped-" + shipped_hash) if shipped_hash else None
    rows.append((scene, u, c, s))
    if c["psnr"] < u["psnr"] + 0.5: failures.append(f"{scene}: PSNR {c['psnr']:.2f} < ulr {u['psnr']:.2f} + 0.5")
    if c["lpips"] > u["lpips"] - 0.02: failures.append(f"{scene}: LPIPS {c['lpips']:.4f} > ulr {u['lpips']:.4f} - 0.02")
    if c["ssim"] < u["ssim"]: failures.append(f"{scene}: SSIM {c['ssim']:.4f} < ulr {u['ssim']:.4f}")

print(f"{'scene':20} {'method':10} {'views':>5} {'PSNR':>7} {'SSIM':>7} {'LPIPS':>7} {'s/view':>7}")
for scene, u, c, s in rows:
    for name, r in (("ulr", u), ("candidate", c), ("shipped", s)):
        if r:
            print(f"{scene:20} {name:10} {int(r['views_ok']):5d} {r['psnr']:7.2f} {r['ssim']:7.4f} {r['lpips']:7.4f} {r['seconds_per_view']:7.2f}")

def mean(key, which):
    vals = [r[which][key] for r in rows]
    return sum(vals) / len(vals)
if shipped_hash:
    cp, cl = mean("psnr", 2), mean("lpips", 2)
    sp, sl = mean("psnr", 3), mean("lpips", 3)
    if not ((cp >= sp and cl < sl) or (cp > sp and cl <= sl)):
        failures.append(f"does not beat the shipped model (mean PSNR {cp:.2f} vs {sp:.2f}, LPIPS {cl:.4f} vs {sl:.4f})")
if failures:
    print("NOT SHIPPED:\n  " + "\n  ".join(failures))
    sys.exit(1)

card = json.load(open(card_path))
variant = card["variant"]
card["weights"] = variant + ".safetensors"
card["holdout_evaluation"] = {
    "protocol": "view_synthesis_eval --protocol holdout (every 5th photo held out of the geometry at prepare)",
    "scenes": [{"scene": scene, "ulr": u, variant: c} for scene, u, c, _ in rows]}
os.makedirs("models", exist_ok=True)
shutil.copyfile(candidate, f"models/{variant}.safetensors.tmp")
os.replace(f"models/{variant}.safetensors.tmp", f"models/{variant}.safetensors")
with open(f"models/{variant}.json.tmp", "w") as f:
    json.dump(card, f, indent=2)
    f.write("\n")
os.replace(f"models/{variant}.json.tmp", f"models/{variant}.json")
print(f"SHIPPED: models/{variant}.safetensors")
EOF
