#include "fvs/exe/render_flags.h"

namespace fvs {

void AddRenderEngineFlags(OptionManager* options, RenderOptions* render) {
  options->AddDefault("max_num_sources", &render->max_num_sources,
                      "the most sources an adaptive K (0, auto) takes");
  options->AddDefault("selection_tolerance", &render->selection_tolerance,
                      "relative depth tolerance for ranking sources");
  options->AddDefault("warp_tolerance", &render->warp_tolerance,
                      "relative occlusion tolerance when warping");
  options->AddDefault("ulr_num_blend", &render->ulr_num_blend,
                      "ulr: the best sources blended per pixel (k-nearest; the rest of "
                      "the K selected weigh 0 there)");
  options->AddDefault("ulr_resolution_weight", &render->ulr_resolution_weight,
                      "ulr: weight of the resolution penalty against the angle (rad)");
  options->AddDefault("interpolation", &render->interpolation,
                      "ulr and nearest: how a source photo is sampled, bicubic or "
                      "bilinear (network methods: bilinear)");
  options->AddDefault("fill_holes", &render->fill_holes,
                      "fill pixels no source sees from the covered pixels around them "
                      "(0: leave them black; reports count them either way)");
  options->AddDefault(
      "use_blurry_sources", &render->use_blurry_sources,
      "rank the photos prepare found blurry (W/fvs/photo_quality.json) as "
      "any other source (0: only where no sharp photo sees)");
  options->AddDefault("device", &render->device,
                      "network methods: auto (CUDA when there is one), cpu or cuda");
  options->AddDefault("feature_cache_mb", &render->feature_cache_mb,
                      "network methods: memory for encoded source features kept across "
                      "targets (0: none)");
  options->AddDefault("tile_size", &render->tile_size,
                      "network methods: blend targets larger than this in tiles of at "
                      "most this size, to bound memory and stay in cache (0: never; -1: "
                      "the network's own, 160 for fvs_agg, 512 for the others)");
  options->AddDefault("tile_overlap", &render->tile_overlap,
                      "network methods: pixels of context around each tile (-1: the "
                      "network's own, 24 for fvs_agg, 32 for the others)");
  options->AddDefault("num_threads", &render->num_threads, "threads (0: all cores)");
}

}  // namespace fvs
