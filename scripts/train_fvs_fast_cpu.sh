#!/usr/bin/env bash
# The CPU training run of fvs_fast, spread over sessions (no GPU machine is lent to this
# project's task): prepares and packs the training scenes of ../shared/datasets (subsampled,
# stereo at 400 px, packed at half size) and four generated scenes, then trains; every
# stage skips what is done, and the trainer resumes from its newest checkpoint, so running
# this again continues where the last run stopped. Niced: it soaks up idle CPU.
#   scripts/train_fvs_fast_cpu.sh [DATASETS_DIR] [WORK_DIR]
# Export weights from the newest checkpoint: rerun the trainer line with --Train.max_steps
# set to the checkpoint's step (it writes WORK_DIR/runs/fvs_fast_w48/model.safetensors).
set -uo pipefail
cd "$(dirname "$0")/.."
DATASETS="$(realpath "${1:-../shared/datasets}")"
WORK="${2:-/work/fvs_training}"
COLMAP="$PWD/build/bin/colmap"
[[ -x "$COLMAP" ]] || scripts/build.sh
mkdir -p "$WORK"/{bin,images,ws,packed,runs}
# A copy, so that rebuilding build/ never changes the binary under a running stage.
cp "$COLMAP" "$WORK/bin/colmap.tmp" && mv -f "$WORK/bin/colmap.tmp" "$WORK/bin/colmap"  # a running binary is busy
cd "$WORK"

# Real scenes (name:every n-th photo). Validation: fox and middlebury_temple (README of
# the datasets); middlebury_dino needs all 48 photos (every 2nd: the mapper fails);
# ethiopian_head is left out: SfM's SIMPLE_RADIAL estimate cannot be
# undistorted at the corners and the images shrink to 160 px.
for spec in middlebury_temple:1 fox:2 sceaux_castle:1 monstree:1 scodive:2 beer:3 \
            mary_rose:2 middlebury_dino:1 alexander:2; do
  scene=${spec%%:*}; step=${spec##*:}
  ws=ws/$scene
  if [[ ! -f $ws/.done ]]; then
    mkdir -p images/$scene
    i=0
    for f in $(ls "$DATASETS/$scene/images" | sort); do
      (( i % step == 0 )) && ln -sf "$DATASETS/$scene/images/$f" images/$scene/$f
      i=$((i + 1))
    done
    echo "prepare $scene ($(ls images/$scene | wc -l) photos)"
    FVS_QUIET=1 nice -n 19 bin/colmap view_synthesis_prepare --image_path images/$scene \
      --workspace_path $ws --max_image_size 800 --Stereo.max_image_size 400 \
      > prepare_$scene.log 2>&1 && touch $ws/.done || { echo "  failed: see prepare_$scene.log"; continue; }
  fi
  [[ -f packed/$scene/scene.safetensors ]] ||
    FVS_QUIET=1 nice -n 19 bin/colmap view_synthesis_pack --workspace_path $ws \
      --output_path packed/$scene --scale 0.5 > /dev/null
done
for seed in 11 12 13 14; do
  [[ -f packed/synthetic_$seed/scene.safetensors ]] && continue
  nice -n 19 bin/colmap view_synthesis_synthetic --output_path ws/synthetic_$seed \
    --SyntheticScene.num_views 30 --SyntheticScene.width 400 --SyntheticScene.height 300 \
    --SyntheticScene.seed $seed --SyntheticScene.write_proxy_mesh 1 \
    --SyntheticScene.path_step_degrees 8 > /dev/null
  FVS_QUIET=1 nice -n 19 bin/colmap view_synthesis_pack --workspace_path ws/synthetic_$seed \
    --output_path packed/synthetic_$seed --scale 1 > /dev/null
done
printf "packed/middlebury_temple\npacked/fox\n" > val.txt
ls -d packed/* | grep -v -e middlebury_temple -e /fox > train.txt

exec nice -n 19 env FVS_NUM_THREADS="$(nproc)" bin/colmap view_synthesis_train \
  --scene_list train.txt --val_scene_list val.txt --output_path runs/fvs_fast_w48 \
  --Train.variant fvs_fast --Train.crop 128 --Train.max_steps 200000 --Train.learning_rate 5e-4 \
  --Train.val_every 250 --Train.val_views 3 --Train.log_every 10 --Train.checkpoint_minutes 10
