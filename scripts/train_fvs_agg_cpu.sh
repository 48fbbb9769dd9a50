#!/usr/bin/env bash
# The CPU training run of fvs_agg (net/aggregate.h), spread over sessions: prepares the
# scenes of ../shared/datasets (subsampled, stereo at 400 px), packs them at half size,
# adds four generated scenes, and trains niced. Every stage skips what is done and the
# trainer resumes from its newest checkpoint, so running this again continues the run.
#   scripts/train_fvs_agg_cpu.sh [DATASETS_DIR] [WORK_DIR]
# Validation scenes (never trained on): fox, middlebury_temple and monstree, prepared with
# every 5th photo held out of the geometry (--holdout_images), the protocol of
# view_synthesis_eval --protocol holdout; their packs are what the trainer validates on
# (it skips the held-out views, which are kept for the reported evaluation).
# FVS_TRAIN_STEPS (default 200000), FVS_RUN (the run folder under runs/, default fvs_agg),
# FVS_INIT (weights a new run starts from; a run with checkpoints resumes from them),
# FVS_CHOICE (the weight of the choice term, train/loss.h; 0 = off), FVS_PACK_SCALE (0.5;
# the real scenes' pack size, 1 = the size view_synthesis_eval renders them at; other
# scales pack into packed_s<scale>/) and FVS_PREPARE_ONLY=1 steer it.
set -uo pipefail
cd "$(dirname "$0")/.."
DATASETS="$(realpath "${1:-../shared/datasets}")"
WORK="${2:-/work/fvs_training}"
NICE="${FVS_NICE:-19}"  # niceness of every stage
COLMAP="$PWD/build/bin/colmap"
# LPIPS-alex (the perceptual loss that can be had here) when the weights are there.
LPIPS="${FVS_LPIPS_PATH:-$(realpath -m ../shared/weights/lpips_alex.safetensors)}"
[[ -f "$LPIPS" ]] || LPIPS=""
# L1 + (1 - SSIM) + LPIPS: LPIPS alone traded SSIM for texture (doc/training.md).
LOSS="${FVS_LOSS:-$([[ -n "$LPIPS" ]] && echo l1+ssim+lpips || echo l1+ssim)}"
[[ -x "$COLMAP" ]] || scripts/build.sh
SCALE="${FVS_PACK_SCALE:-0.5}"
PACKED=packed
[[ "$SCALE" == "0.5" ]] || PACKED="packed_s$SCALE"
mkdir -p "$WORK"/{bin,images,ws,packed,runs} "$WORK/$PACKED"
# A copy, so that rebuilding build/ never changes the binary under a running stage.
# (Copied then renamed: a binary still running from an earlier run is "text file busy".)
cp "$COLMAP" "$WORK/bin/colmap.tmp" && mv -f "$WORK/bin/colmap.tmp" "$WORK/bin/colmap"
cd "$WORK"

# scene:every n-th photo:holdout (1 = every 5th of the chosen photos held out).
prepare_scene() {
  local scene=$1 step=$2 holdout=$3 ws=ws/$1
  [[ -f $ws/.done ]] && return 0
  mkdir -p images/$scene
  local i=0 j=0 held=()
  for f in $(ls "$DATASETS/$scene/images" | sort); do
    if (( i % step == 0 )); then
      ln -sf "$DATASETS/$scene/images/$f" images/$scene/$f
      (( holdout && j % 5 == 0 )) && held+=("$f")
      j=$((j + 1))
    fi
    i=$((i + 1))
  done
  local args=()
  if (( holdout )); then
    printf "%s\n" "${held[@]}" > images/$scene.holdout.txt
    args=(--holdout_images images/$scene.holdout.txt)
  fi
  echo "prepare $scene ($(ls images/$scene | wc -l) photos, ${#held[@]} held out)"
  FVS_QUIET=1 nice -n "$NICE" bin/colmap view_synthesis_prepare --image_path images/$scene \
    --workspace_path $ws --max_image_size 800 --Stereo.max_image_size 400 "${args[@]}" \
    > prepare_$scene.log 2>&1 && touch $ws/.done || echo "  failed: see prepare_$scene.log"
}

pack_scene() {
  local scene=$1
  [[ -f ws/$scene/.done && ! -f $PACKED/$scene/scene.safetensors ]] || return 0
  FVS_QUIET=1 nice -n "$NICE" bin/colmap view_synthesis_pack --workspace_path ws/$scene \
    --output_path $PACKED/$scene --scale "$SCALE" > /dev/null
}

for seed in 11 12 13 14; do
  [[ -f packed/synthetic_$seed/scene.safetensors ]] && continue
  nice -n "$NICE" bin/colmap view_synthesis_synthetic --output_path ws/synthetic_$seed \
    --SyntheticScene.num_views 30 --SyntheticScene.width 400 --SyntheticScene.height 300 \
    --SyntheticScene.seed $seed --SyntheticScene.write_proxy_mesh 1 \
    --SyntheticScene.path_step_degrees 8 > /dev/null
  FVS_QUIET=1 nice -n "$NICE" bin/colmap view_synthesis_pack --workspace_path ws/synthetic_$seed \
    --output_path packed/synthetic_$seed --scale 1 > /dev/null
done
# The generated scenes are packed at their own size whatever the scale of the real ones.
if [[ "$PACKED" != packed ]]; then
  for seed in 11 12 13 14; do
    ln -sfn "$PWD/packed/synthetic_$seed" "$PACKED/synthetic_$seed"
  done
fi

# Validation first (small), then training scenes, smallest first.
# middlebury_dino (a black backdrop like the temple's) and wall_clock fail in the mapper
# with every 2nd photo, so they take all of them (slower to prepare).
for spec in middlebury_temple:1:1 monstree:1:1 fox:2:1 sceaux_castle:1:0 \
            beer:3:0 scodive:3:0 alexander:2:0 mary_rose:3:0 gold_cape:4:0 \
            middlebury_dino:1:0 wall_clock:1:0; do
  IFS=: read -r scene step holdout <<< "$spec"
  prepare_scene "$scene" "$step" "$holdout"
  pack_scene "$scene"
done
[[ "${FVS_PREPARE_ONLY:-0}" == "1" ]] && exit 0

LISTS="${PACKED#packed}"  # val.txt, train.txt; val_s1.txt, train_s1.txt at scale 1
# Validation on the half-size packs whatever the training scale: a pass over the
# full-size ones took over 20 minutes on this CPU (the held-out views at full size are
# scripts/ship_model.sh's job).
printf "packed/middlebury_temple\npacked/fox\npacked/monstree\n" > val$LISTS.txt
ls -d $PACKED/*/ | sed 's#/$##' | grep -v -e middlebury_temple -e /fox -e /monstree \
  > train$LISTS.txt

# Passive OpenMP waits: with anything else running, spinning threads that wait for a core
# made steps several times slower on this 2-core machine.
exec nice -n "$NICE" env FVS_NUM_THREADS="${FVS_NUM_THREADS:-$(nproc)}" \
  OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}" FVS_LPIPS_PATH="$LPIPS" \
  bin/colmap view_synthesis_train \
  --scene_list train$LISTS.txt --val_scene_list val$LISTS.txt --output_path "runs/${FVS_RUN:-fvs_agg}" \
  ${FVS_INIT:+--Train.init_weights "$FVS_INIT"} \
  --Train.variant fvs_agg --Train.crop 128 --Train.max_steps "${FVS_TRAIN_STEPS:-200000}" \
  --Train.batch_size 4 --Train.learning_rate "${FVS_LR:-2e-4}" --Train.val_every 250 \
  --Train.val_views 4 --Train.log_every 25 --Train.checkpoint_minutes 10 --Train.loss "$LOSS" \
  --Train.choice_weight "${FVS_CHOICE:-0}"
