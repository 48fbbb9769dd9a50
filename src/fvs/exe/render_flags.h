// The flags of the renderer's engine, registered once for every command that renders
// (view_synthesis, view_synthesis_eval): sources, tolerances, holes, device, tiles,
// feature cache and threads, bound to a RenderOptions. K, the weights and the precision
// are not here: view_synthesis binds them to its RenderOptions, view_synthesis_eval to
// the configuration it evaluates (or sweeps).
#pragma once

#include "fvs/render/method.h"
#include "fvs/util/option_manager.h"

namespace fvs {

void AddRenderEngineFlags(OptionManager* options, RenderOptions* render);

}  // namespace fvs
