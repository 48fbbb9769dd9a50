// The tiny networks the trainer tests train: a few thousand parameters, so a step takes
// milliseconds on 2 cores.
#pragma once

#include <string>

#include "fvs/train/trainer.h"

namespace fvs::testing {

inline constexpr char kTinyNet[] =
    R"({"variant": "fvs_fast", "feature_channels": 8, "encoder_channels": [8, 16, 16],
        "encoder_convs": [1, 1, 1], "blend_channels": [8, 16, 16], "blend_convs_per_stage": 2})";

// The same without the colour skip and the priors: the output is the network's alone, so
// it starts from noise (its loss must fall a lot) and reduced precision shows.
inline constexpr char kTinyNetNoSkip[] =
    R"({"variant": "fvs_fast", "feature_channels": 8, "encoder_channels": [8, 16, 16],
        "encoder_convs": [1, 1, 1], "blend_channels": [8, 16, 16], "blend_convs_per_stage": 2,
        "rgb_skip": false, "mask_prior": 0, "ulr_prior": 0})";

// A run of kTinyNet on the packs `scene_list` names, into `output_path`: two sources,
// 32-pixel crops, quiet, on the CPU. One thread: on a loaded 2-core machine OpenMP's
// spinning threads cost more than they give at these sizes (and the resume tests need
// the same count in every run anyway). The caller sets the steps.
inline TrainOptions TinyTrainOptions(const std::string& scene_list,
                                     const std::string& output_path) {
  TrainOptions o;
  o.scene_list = scene_list;
  o.output_path = output_path;
  o.model_config_json = kTinyNet;
  o.num_sources = 2;
  o.crop = 32;
  o.quiet = true;
  o.num_threads = 1;
  o.device = "cpu";
  return o;
}

}  // namespace fvs::testing
