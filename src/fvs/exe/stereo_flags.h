// The flags of the built-in stereo and mesher, registered once for the commands that run
// them: --PlanarPrior.* (mvs/planar_prior.h; view_synthesis_stereo,
// view_synthesis_prepare) and --DelaunayMeshing.* (mvs/delaunay.h, COLMAP's names and
// defaults; view_synthesis_mesher, view_synthesis_prepare).
#pragma once

#include "fvs/mvs/delaunay.h"
#include "fvs/mvs/planar_prior.h"
#include "fvs/util/option_manager.h"

namespace fvs {

void AddPlanarPriorFlags(OptionManager* options, mvs::PlanarPriorOptions* prior);
void AddDelaunayMeshingFlags(OptionManager* options, mvs::DelaunayMeshingOptions* o);

}  // namespace fvs
