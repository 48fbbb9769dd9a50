// The planar-prior flags of the built-in stereo (mvs/planar_prior.h), registered once for
// the commands that run it (view_synthesis_stereo, view_synthesis_prepare) as
// --PlanarPrior.*.
#pragma once

#include "fvs/mvs/planar_prior.h"
#include "fvs/util/option_manager.h"

namespace fvs {

void AddPlanarPriorFlags(OptionManager* options, mvs::PlanarPriorOptions* prior);

}  // namespace fvs
