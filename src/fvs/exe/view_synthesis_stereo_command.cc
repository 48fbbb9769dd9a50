// colmap view_synthesis_stereo --workspace_path W: CPU PatchMatch stereo on a COLMAP
// dense workspace (what image_undistorter writes). Writes
// W/stereo/{depth_maps,normal_maps}/ <name>.{photometric,geometric}.bin in COLMAP's
// format, so that
//   colmap stereo_fusion --workspace_path W --workspace_format COLMAP
//                        --input_type geometric --output_path W/fused.ply
// fuses them unchanged. Images whose maps exist are skipped unless
// --PatchMatchStereo.overwrite 1 (a killed run resumes where it stopped).
#include <string>

#include "fvs/controllers/workspace_stages.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/stereo_flags.h"
#include "fvs/mvs/patch_match_stereo.h"
#include "fvs/util/error.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunViewSynthesisStereo(int argc, char** argv) {
  std::string workspace_path;
  std::string workspace_format = "COLMAP";
  mvs::PatchMatchStereoOptions stereo;
  mvs::PatchMatchOptions& pm = stereo.patch_match;
  int seed = 0;
  OptionManager options(
      "view_synthesis_stereo",
      "CPU PatchMatch multi-view stereo (photometric, then geometric consistency) on a "
      "COLMAP dense workspace; writes COLMAP depth and normal maps for stereo_fusion.");
  options.AddRequired(
      "workspace_path", &workspace_path,
      "dense workspace (images/, sparse/, optional stereo/patch-match.cfg)");
  options.AddDefault("workspace_format", &workspace_format, "only COLMAP is supported");
  const std::string p = "PatchMatchStereo.";
  options.AddDefault(p + "max_image_size", &stereo.max_image_size,
                     "largest image side for stereo (0 or -1 = full size)");
  options.AddDefault(p + "geom_consistency", &stereo.geom_consistency,
                     "run the geometric-consistency pass (writes *.geometric.bin)");
  options.AddDefault(p + "max_num_sources", &stereo.max_num_sources,
                     "source views scored per pixel (best of patch-match.cfg)");
  options.AddDefault(
      p + "min_triangulation_angle", &stereo.min_triangulation_angle,
      "__auto__ sources: minimum triangulation angle of shared points (deg)");
  options.AddDefault(p + "overwrite", &stereo.overwrite, "recompute existing maps");
  AddPlanarPriorFlags(&options, &stereo.planar_prior);
  options.AddDefault(p + "window_radius", &pm.window_radius,
                     "NCC window radius (pixels)");
  options.AddDefault(p + "window_step", &pm.window_step, "NCC window sampling step");
  options.AddDefault(p + "num_iterations", &pm.num_iterations, "photometric iterations");
  options.AddDefault(p + "sigma_color", &pm.sigma_color,
                     "bilateral NCC weights: grey sigma (0 = uniform window)");
  options.AddDefault(p + "sigma_spatial", &pm.sigma_spatial,
                     "bilateral NCC weights: spatial sigma (0 = window_radius)");
  options.AddDefault(p + "fast_refinement", &pm.fast_refinement,
                     "refinement from converged planes: 4 neighbours, no random plane");
  options.AddDefault(p + "num_geometric_iterations", &pm.num_geometric_iterations,
                     "geometric-consistency iterations");
  options.AddDefault(p + "top_k", &pm.top_k, "cost = mean of the best k source costs");
  options.AddDefault(
      p + "min_texture_std", &pm.min_texture_std,
      "grey std of a window below which a pixel is textureless (no depth)");
  options.AddDefault(p + "max_window_scale", &pm.max_window_scale,
                     "a textureless window spreads over up to this many times its side "
                     "(1, 2, 4, 8, 16; 1 = never)");
  options.AddDefault(p + "geom_consistency_regularizer", &pm.geom_consistency_regularizer,
                     "weight of the reprojection error in the geometric cost");
  options.AddDefault(p + "geom_consistency_max_cost", &pm.geom_consistency_max_cost,
                     "reprojection error cap (pixels)");
  options.AddDefault(p + "filter", &pm.filter, "zero out unconfirmed pixels");
  options.AddDefault(p + "filter_min_ncc", &pm.filter_min_ncc, "filter: minimum NCC");
  options.AddDefault(p + "filter_min_triangulation_angle",
                     &pm.filter_min_triangulation_angle,
                     "filter: minimum triangulation angle (deg)");
  options.AddDefault(p + "filter_min_num_consistent", &pm.filter_min_num_consistent,
                     "filter: minimum number of confirming sources");
  options.AddDefault(p + "filter_geom_consistency_max_cost",
                     &pm.filter_geom_consistency_max_cost,
                     "filter: maximum reprojection error (pixels)");
  options.AddDefault(p + "num_threads", &pm.num_threads, "-1 = all cores");
  options.AddDefault(p + "seed", &seed, "random seed (>= 0)");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(workspace_path, "view_synthesis_stereo");
  Require(workspace_format == "COLMAP", "workspace_format",
          "only COLMAP workspaces are supported, got '" + workspace_format + "'");
  Require(seed >= 0, p + "seed", "must be >= 0");
  pm.seed = static_cast<uint64_t>(seed);
  if (stereo.max_image_size < 0) stereo.max_image_size = 0;  // COLMAP's -1 = full size

  RunBuiltinStereo(workspace_path, stereo);
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_stereo",
                     "CPU PatchMatch stereo: COLMAP depth/normal maps for stereo_fusion",
                     RunViewSynthesisStereo);

}  // namespace fvs
