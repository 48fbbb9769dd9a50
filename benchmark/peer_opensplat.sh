#!/usr/bin/env bash
# The per-scene Gaussian splatting peer of issue 41: OpenSplat, trained on this CPU from
# the SfM model of a prepared workspace with the photos held out of the geometry removed,
# then rendering exactly those views, scored as `view_synthesis_eval` scores ours
# (build/bin/render_scores_benchmark). OpenSplat is AGPL: it is built beside the project
# for measurement only, never vendored, never copied from. The one local change to it is
# below (write the final validation render to a file), made by this script in the peer's
# own tree.
#
#   benchmark/peer_opensplat.sh build
#   benchmark/peer_opensplat.sh run W OUT MINUTES [MINUTES ...]
#
# build: $FVS_PEER_DIR (default ../peer) gets opensplat/, nanoflann/, cxxopts/ from
#   $OPENSPLAT_GIT, $NANOFLANN_GIT, $CXXOPTS_GIT (git repositories or URLs; tags v1.5.5
#   and v3.2.0 as the peer's CMakeLists asks) and builds build/opensplat for the CPU
#   against Debian's LibTorch (apt: libopencv-dev libglm-dev nlohmann-json3-dev).
# run: W was prepared with --holdout_images. For each budget (minutes of wall time on this
#   machine) a fresh training at the peer's defaults but for its step count, which fits
#   the budget (as a new user would run it; below). The step count comes from the rate
#   of the previous run (the first calibrates on 100 steps), so a run's wall time may
#   miss its budget: each line says what it took. Each run writes OUT/<minutes>min/{train.log,
#   splat.ply,renders/,scores.csv} and one line to OUT/peer.txt with the steps, the wall
#   and CPU seconds, and the scores. On the CPU the peer runs on about one core (its
#   CPU seconds equal its wall seconds), so one other single-threaded job beside it
#   leaves its figures as they are; anything more would not.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
PEER="$(realpath -m "${FVS_PEER_DIR:-../peer}")"
OPENSPLAT="$PEER/build/opensplat"
BIN="${FVS_BENCH_BIN:-$ROOT/${FVS_BUILD_DIR:-build}/bin}"  # a copy keeps a long run safe from rebuilds
SCORES="$BIN/render_scores_benchmark"
COLMAP="$BIN/colmap"
LPIPS="$(realpath -m "${FVS_LPIPS_PATH:-../shared/weights/lpips_alex.safetensors}")"

build_peer() {
  mkdir -p "$PEER"
  local name src tag
  for spec in "opensplat ${OPENSPLAT_GIT:-https://github.com/pierotofy/OpenSplat} HEAD" \
              "nanoflann ${NANOFLANN_GIT:-https://github.com/jlblancoc/nanoflann} v1.5.5" \
              "cxxopts ${CXXOPTS_GIT:-https://github.com/jarro2783/cxxopts} v3.2.0"; do
    read -r name src tag <<< "$spec"
    [[ -d $PEER/$name ]] && continue
    git clone -q "$src" "$PEER/$name.git"
    git -C "$PEER/$name.git" archive --prefix="$name/" "$tag" | tar x -C "$PEER"
    rm -rf "$PEER/$name.git"
  done
  # The local change: after the final validation loss, write that render as
  # <--val-render>/final.png (the peer writes validation renders only every 10 steps).
  if ! grep -q fvs-peer-final "$PEER/opensplat/opensplat.cpp"; then
    sed -i '/validation loss: /a\            if (!valRender.empty()) { /* fvs-peer-final */ cv::Mat im = tensorToImage(rgb.detach().cpu()); cv::cvtColor(im, im, cv::COLOR_RGB2BGR); cv::imwrite((fs::path(valRender) / "final.png").string(), im); }' \
      "$PEER/opensplat/opensplat.cpp"
  fi
  # Debian's nlohmann-json in place of the peer's download.
  mkdir -p "$PEER/json_shim"
  printf 'cmake_minimum_required(VERSION 3.24)\nproject(json_shim)\nfind_package(nlohmann_json 3 REQUIRED GLOBAL)\n' \
    > "$PEER/json_shim/CMakeLists.txt"
  cmake -S "$PEER/opensplat" -B "$PEER/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DGPU_RUNTIME=CPU -DFETCHCONTENT_FULLY_DISCONNECTED=ON \
    -DFETCHCONTENT_SOURCE_DIR_NANOFLANN="$PEER/nanoflann" \
    -DFETCHCONTENT_SOURCE_DIR_CXXOPTS="$PEER/cxxopts" \
    -DFETCHCONTENT_SOURCE_DIR_NLOHMANN_JSON="$PEER/json_shim" > "$PEER/cmake.log"
  ninja -C "$PEER/build" opensplat
}

# The peer's options: its defaults (as a new user runs it) but for the number of steps,
# which fits the budget. Its schedule trains at a quarter of the size for the first 3000
# steps and at half for the next 3000; the views are rendered at full size
# (--num-downscales 0 at render time; the Gaussians are the same).
train_args() { echo "-n $1"; }
render_args() { echo "-n $1 --num-downscales 0"; }

make_projects() {
  local ws=$1 out=$2
  [[ -f $ws/fvs/holdout.txt && -f $ws/sparse/images.bin ]] || {
    echo "ERROR: $ws: not a workspace prepared with --holdout_images" >&2; exit 2; }
  if [[ ! -f $out/train/sparse/0/images.bin ]]; then
    mkdir -p "$out/train/sparse/0" "$out/eval/sparse"
    ln -sfn "$(realpath "$ws/images")" "$out/train/images"
    ln -sfn "$(realpath "$ws/images")" "$out/eval/images"
    ln -sfn "$(realpath "$ws/sparse")" "$out/eval/sparse/0"
    "$COLMAP" image_deleter --input_path "$ws/sparse" --output_path "$out/train/sparse/0" \
      --image_names_path "$ws/fvs/holdout.txt" > "$out/image_deleter.log" 2>&1
  fi
}

# train OUT_DIR STEPS: one training run; prints "steps wall_s cpu_s".
train() {
  local dir=$1 n=$2 t0 t1
  mkdir -p "$dir"
  t0=$(date +%s.%N)
  # shellcheck disable=SC2046
  /usr/bin/time -f "%U %S" -o "$dir/cpu.txt" "$OPENSPLAT" "$OUT/train" -o "$dir/splat.ply" \
    --keep-crs --cpu $(train_args "$n") > "$dir/train.log" 2>&1
  t1=$(date +%s.%N)
  echo "$n $(echo "$t1 - $t0" | bc) $(awk '{print $1 + $2}' "$dir/cpu.txt")"
}

render_views() {
  local dir=$1 n=$2 name tmp
  mkdir -p "$dir/renders"
  while read -r name; do
    [[ -n $name ]] || continue
    tmp=$dir/renders/tmp
    rm -rf "$tmp"
    # shellcheck disable=SC2046
    "$OPENSPLAT" "$OUT/eval" --resume "$dir/splat.ply" -o "$tmp/copy.ply" --keep-crs --cpu \
      --val-image "$name" --val-render "$tmp" $(render_args "$n") > "$dir/render.log" 2>&1
    mv "$tmp/final.png" "$dir/renders/$name.png"
    rm -rf "$tmp"
  done < "$WS/fvs/holdout.txt"
}

case "${1:-}" in
  build) build_peer ;;
  run)
    (( $# >= 4 )) || { echo "usage: $0 run W OUT MINUTES [MINUTES ...]" >&2; exit 2; }
    WS=$(realpath "$2"); OUT=$(realpath -m "$3"); shift 3
    [[ -x $OPENSPLAT ]] || { echo "ERROR: $OPENSPLAT missing: run $0 build" >&2; exit 2; }
    [[ -x $SCORES ]] || { echo "ERROR: $SCORES missing: run scripts/build.sh" >&2; exit 2; }
    make_projects "$WS" "$OUT"
    { echo "date: $(date -u +%FT%TZ)  workspace: $WS"
      echo "cpu: $(nproc) x$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)  load: $(cut -d' ' -f1-3 /proc/loadavg)"
    } >> "$OUT/peer.txt"
    read -r _ wall _ <<< "$(train "$OUT/calibration" 100)"
    quarter=$(echo "$wall / 100" | bc -l)  # seconds per step at a quarter of the size
    for minutes in "$@"; do
      # Steps within the budget (less a tenth), a step at half size costing 4 and at full
      # size 16 of the quarter-size steps (pixels), the peer's schedule as above.
      steps=$(awk -v b="$(echo "$minutes * 60 * 0.9" | bc -l)" -v q="$quarter" 'BEGIN {
        n = 0; t = 0
        while (1) { c = q * (n < 3000 ? 1 : n < 6000 ? 4 : 16); if (t + c > b) break; t += c; n++ }
        print n }')
      dir=$OUT/${minutes}min
      read -r steps wall cpu <<< "$(train "$dir" "$steps")"
      # What this run's steps cost, for the next budget (its own mix of sizes).
      quarter=$(awk -v n="$steps" -v w="$wall" 'BEGIN {
        u = (n < 3000 ? n : 3000) + 4 * (n < 3000 ? 0 : (n < 6000 ? n - 3000 : 3000)) + 16 * (n > 6000 ? n - 6000 : 0)
        print w / u }')
      render_views "$dir" "$steps"
      "$SCORES" --workspace_path "$WS" --renders_path "$dir/renders" --lpips_path "$LPIPS" \
        --seconds "$wall" --label "opensplat ${minutes}min" > "$dir/scores.txt"
      printf '%s min: %s steps, %.0f s wall, %.0f s CPU; %s\n' "$minutes" "$steps" "$wall" \
        "$cpu" "$(tail -1 "$dir/scores.txt")" | tee -a "$OUT/peer.txt"
    done
    ;;
  *) echo "usage: $0 build | run W OUT MINUTES [MINUTES ...]" >&2; exit 2 ;;
esac
