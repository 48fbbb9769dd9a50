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

void AddDelaunayMeshingFlags(OptionManager* options, mvs::DelaunayMeshingOptions* o) {
  const std::string p = "DelaunayMeshing.";
  options->AddDefault(p + "max_proj_dist", &o->max_proj_dist,
                      "merge points that reproject within this many pixels of a cell's "
                      "vertices in every image that sees them (0: keep all points)");
  options->AddDefault(p + "max_depth_dist", &o->max_depth_dist,
                      "... and whose relative depth differs by less than this");
  options->AddDefault(
      p + "visibility_sigma", &o->visibility_sigma,
      "points seen by few images weigh less: 1 - exp(-n^2 / (2 sigma^2))");
  options->AddDefault(
      p + "distance_sigma_factor", &o->distance_sigma_factor,
      "free-space falloff near a point, times the 25th percentile edge length");
  options->AddDefault(p + "quality_regularization", &o->quality_regularization,
                      "weight of the surface-quality (smoothness) term");
  options->AddDefault(p + "max_side_length_factor", &o->max_side_length_factor,
                      "drop faces whose longest side exceeds this factor times ...");
  options->AddDefault(p + "max_side_length_percentile", &o->max_side_length_percentile,
                      "... this percentile of the faces' longest sides");
  options->AddDefault(p + "isolated_point_neighbors", &o->isolated_point_neighbors,
                      "not in COLMAP: drop points far from their k nearest points before "
                      "meshing (0: keep all)");
  options->AddDefault(p + "isolated_point_factor", &o->isolated_point_factor,
                      "... farther than this factor times the median neighbour distance");
  options->AddDefault(p + "max_side_spacing_factor", &o->max_side_spacing_factor,
                      "not in COLMAP: drop faces longer than this factor times the local "
                      "point spacing at their vertices (0: off)");
  options->AddDefault(
      p + "sparse_min_track_length", &o->sparse_min_track_length,
      "not in COLMAP: add the SfM points seen by at least this many fused "
      "images (stereo/fusion.cfg; 0: fused points only)");
  options->AddDefault(p + "sparse_max_error", &o->sparse_max_error,
                      "... whose reprojection error is at most this many pixels");
}

}  // namespace fvs
