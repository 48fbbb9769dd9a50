// The tiny networks the trainer tests train: a few thousand parameters, so a step takes
// milliseconds on 2 cores.
#pragma once

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

}  // namespace fvs::testing
