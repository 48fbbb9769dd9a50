// The network as a rendering method (`--method fvs`, or a variant name such as
// `fvs_fast`): the shared geometric front end (PrepareTarget), then the sources' features
// encoded once and cached across targets, warped into the target with grid_sample,
// blended by the recurrent network. No torch in this header.
#pragma once

#include <memory>

#include "fvs/render/method.h"

namespace fvs {

// Loads options.model_path, or the shipped model of `requested` when none is given
// (ShippedModelPath); throws fvs::Error naming the file on missing or mismatched weights.
// `requested` is the --method name: "fvs" accepts any variant, a variant name must match
// the weights' config.
std::unique_ptr<Method> CreateFvsMethod(const std::string& requested,
                                        const RenderOptions& options);

// The shipped weights of a variant, <variant>.safetensors, in the first folder that has
// them: $FVS_MODEL_DIR, then <executable>/../share/colmap-fvs/models: <prefix>/share/...
// in an installed tree, build/share/colmap-fvs/models (a link to the source tree's
// models/) in the build tree. No source path is compiled in. Empty when none has them.
std::string ShippedModelPath(const std::string& variant);

// The weights a network method uses without --model_path: the scene's fine-tuned
// <variant>.safetensors in scene_model_dir when there is one, else ShippedModelPath.
// *is_scene_model (optional) tells which. Empty when there are none.
std::string DefaultModelPath(const std::string& variant,
                             const std::string& scene_model_dir,
                             bool* is_scene_model = nullptr);

}  // namespace fvs
