// colmap view_synthesis_prepare --image_path P --workspace_path W
//
// Photos -> ready scene: SfM, undistortion, dense stereo, fusion, meshing, backdrop,
// source depth cache, each stage skipped when it is current and a killed run resumed:
// PrepareWorkspace (controllers/prepare_workspace.h) does the work and states the rules.
#include "fvs/controllers/prepare_workspace.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/stereo_flags.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunPrepare(int argc, char** argv) {
  PrepareWorkspaceOptions o;
  OptionManager options(
      "view_synthesis_prepare",
      "Photos to a ready view-synthesis scene: SfM, undistortion, dense "
      "stereo, fusion, meshing, backdrop, source depth cache. Finished stages are "
      "skipped; a killed run resumes.");
  options.AddRequired("image_path", &o.image_path, "folder of the input photos");
  options.AddRequired("workspace_path", &o.workspace_path, "output dense workspace");
  options.AddDefault(
      "Matching.type", &o.matcher,
      "auto (every pair up to 200 images, 1000 with a CUDA COLMAP; beyond, "
      "sequential for consecutive numbered frames), exhaustive, sequential "
      "(neighbours in name order, with loop closure); when mapping misses "
      "photos after sequential, every pair is matched and mapped again");
  options.AddDefault("ImageReader.camera_model", &o.camera_model, "COLMAP camera model");
  options.AddDefault("ImageReader.single_camera", &o.single_camera,
                     "one camera for all photos");
  options.AddDefault("max_image_size", &o.max_image_size,
                     "longest side for SIFT and undistortion");
  options.AddDefault("Stereo.backend", &o.stereo_backend,
                     "auto (COLMAP when it has CUDA), colmap, builtin");
  options.AddDefault("Stereo.max_image_size", &o.stereo_max_image_size,
                     "longest side for stereo (0 = undistorted size)");
  options.AddDefault("Stereo.max_window_scale", &o.stereo_max_window_scale,
                     "built-in stereo: a textureless pixel's window may spread over up "
                     "to this many times its side (1, 2, 4, 8, 16; 1 = never)");
  AddPlanarPriorFlags(&options, &o.planar_prior);
  AddDelaunayMeshingFlags(&options, &o.meshing);
  options.AddDefault("Fusion.min_num_pixels", &o.fusion_min_num_pixels,
                     "views whose depths must agree on a fused point (COLMAP's "
                     "StereoFusion.min_num_pixels)");
  options.AddDefault("Backdrop.enabled", &o.backdrop.enabled,
                     "fit what lies beyond the mesh (a black cloth, a table top) to the "
                     "photos before falling back to infinity");
  options.AddDefault("Backdrop.subdivisions", &o.backdrop.subdivisions,
                     "directions of the backdrop: 10 * 4^s + 2");
  options.AddDefault("Backdrop.max_image_size", &o.backdrop.max_image_size,
                     "longest side of the photos the backdrop fit compares");
  options.AddDefault("Backdrop.min_views", &o.backdrop.min_views,
                     "photos that must see a backdrop point");
  options.AddDefault("Backdrop.infinity_margin", &o.backdrop.infinity_margin,
                     "colour std by which infinity must agree better to be kept");
  options.AddDefault("Backdrop.max_colour_std", &o.backdrop.max_colour_std,
                     "directions whose colours disagree more at every radius are "
                     "left to infinity");
  options.AddDefault("PhotoQuality.blur_ratio", &o.photo_quality.blur_ratio,
                     "a photo whose sharpness is below this times the set's median is "
                     "blurry: a source of last resort (0: none is)");
  options.AddDefault("PhotoQuality.duplicate_distance",
                     &o.photo_quality.duplicate_distance,
                     "near-duplicates: centres closer than this times the median "
                     "spacing of the photos ...");
  options.AddDefault("PhotoQuality.duplicate_degrees", &o.photo_quality.duplicate_degrees,
                     "... looking within this many degrees of each other");
  options.AddDefault("Consistency.enabled", &o.consistency.enabled,
                     "remove the mesh's faces the photos contradict: a surface across "
                     "empty space shows different colours in different photos "
                     "(mvs/face_consistency.h)");
  options.AddDefault("Consistency.max_image_size", &o.consistency.max_image_size,
                     "longest side of the photos compared");
  options.AddDefault("Consistency.num_neighbors", &o.consistency.num_neighbors,
                     "photos each photo is compared with");
  options.AddDefault("Consistency.depth_tolerance", &o.consistency.depth_tolerance,
                     "relative depth within which another photo's mesh depth says it "
                     "sees the point");
  options.AddDefault("Consistency.max_colour_difference",
                     &o.consistency.max_colour_difference,
                     "mean |RGB difference| (0-1) above which a face is removed");
  options.AddDefault("Consistency.min_samples", &o.consistency.min_samples,
                     "photo pixel pairs a face needs before it is judged");
  options.AddDefault("Refine.enabled", &o.refine.enabled,
                     "move the mesh's vertices to where the photos agree "
                     "(mvs/mesh_refinement.h; off: it did not pay on held-out views, "
                     "doc/real_scenes.md)");
  options.AddDefault("Refine.max_image_size", &o.refine.max_image_size,
                     "longest side of the photos at the finest level");
  options.AddDefault("Refine.num_levels", &o.refine.num_levels,
                     "levels coarse to fine, the photo size halved per level");
  options.AddDefault("Refine.num_iterations", &o.refine.num_iterations,
                     "searches along the normals per level");
  options.AddDefault("Refine.patch_size", &o.refine.patch_size,
                     "samples per side of the compared patch (odd)");
  options.AddDefault("Refine.search_steps", &o.refine.search_steps,
                     "offsets of half a pixel tried on each side of a vertex");
  options.AddDefault("Refine.num_sources", &o.refine.num_sources,
                     "photos compared with each vertex's reference photo");
  options.AddDefault("Refine.min_ncc", &o.refine.min_ncc,
                     "mean NCC a vertex's best offset must reach to count");
  options.AddDefault("Refine.smoothness", &o.refine.smoothness,
                     "weight of each mesh edge in the regularisation (data weight <= 1)");
  options.AddDefault("Refine.max_edge_pixels", &o.refine.max_edge_pixels,
                     "before each level, split edges longer than this in a photo at the "
                     "level's size (0: no subdivision)");
  options.AddDefault("Refine.max_vertices", &o.refine.max_vertices,
                     "subdivide no further once the mesh has this many vertices");
  options.AddDefault("Refine.max_seconds", &o.refine.max_seconds,
                     "time bound of the refinement (it stops after the iteration that "
                     "crosses it)");
  options.AddDefault(
      "Mesher.backend", &o.mesher_backend,
      "auto (builtin: COLMAP's algorithm with SfM points), colmap, builtin");
  options.AddDefault(
      "holdout_images", &o.holdout_images,
      "images registered by SfM but kept out of stereo, fusion and meshing: "
      "a file with one name per line, or a comma-separated list");
  options.AddDefault("num_threads", &o.num_threads, "-1 = all cores");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(o.workspace_path, "view_synthesis_prepare");
  PrepareWorkspace(o);
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND(
    "view_synthesis_prepare",
    "photos -> ready scene (SfM, stereo, fusion, mesh, backdrop, depth cache)",
    RunPrepare);

}  // namespace fvs
