// Pixels that no source sees (coverage 0: outside every source's view, or occluded in all
// of them) are black in a raw render. In real scenes they are mostly sky and distant
// background the mesh does not reach, and a black hole costs more than any plausible
// colour (sceaux_castle, doc/evaluation.md). FillHoles gives them colours pushed and
// pulled from the covered pixels around them (Gortler et al., "The Lumigraph", 1996): a
// pyramid of coverage-weighted averages, each hole taking the colour of the finest level
// that has data near it. No learnt prior, so it cannot paint a black backdrop sky-bright.
#pragma once

#include "fvs/util/image.h"

namespace fvs {

// color: any channels; coverage: 1 channel of the same size, > 0 = covered (weights are
// clamped to [0, 1]). Covered pixels keep their colour exactly; with no covered pixel at
// all the image is left as it is. Non-finite colours count as holes. With the target
// depth (1 channel, 0 = no surface), holes without a surface are filled from covered
// pixels without a surface only (when there are any), so that a backdrop beyond the mesh
// does not take the colour of the object in front of it.
void FillHoles(const Image& coverage, const Image* depth, Image* color);

}  // namespace fvs
