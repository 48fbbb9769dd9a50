#include "fvs/exe/stereo_flags.h"

namespace fvs {

void AddPlanarPriorFlags(OptionManager* options, mvs::PlanarPriorOptions* prior) {
  const std::string p = "PlanarPrior.";
  options->AddDefault(p + "enabled", &prior->enabled,
                      "fill what the geometric pass left empty from planar priors");
  options->AddDefault(p + "cell_size", &prior->cell_size,
                      "finest support cell (pixels); each level doubles it");
  options->AddDefault(p + "num_levels", &prior->num_levels, "support cell levels");
  options->AddDefault(p + "max_support_cost", &prior->max_support_cost,
                      "largest PatchMatch cost of a supporting pixel");
  options->AddDefault(p + "max_plane_residual", &prior->max_plane_residual,
                      "supports within this relative depth of their plane");
  options->AddDefault(p + "min_cos_incidence", &prior->min_cos_incidence,
                      "smallest cosine between a plane's normal and the ray");
  options->AddDefault(p + "window_radius", &prior->window_radius,
                      "grey test window radius");
  options->AddDefault(p + "max_grey_difference", &prior->max_grey_difference,
                      "grey test: largest mean |reference - source| (grey in [0, 1])");
  options->AddDefault(p + "depth_tolerance", &prior->depth_tolerance,
                      "relative depth within which a source's map confirms the point");
  options->AddDefault(p + "min_num_consistent", &prior->min_num_consistent,
                      "sources that must confirm a filled pixel");
}

}  // namespace fvs
