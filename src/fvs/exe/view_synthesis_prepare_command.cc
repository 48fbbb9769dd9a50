// colmap view_synthesis_prepare --image_path P --workspace_path W
//
// Photos -> ready scene: feature extraction, matching, mapping, undistortion (COLMAP),
// dense stereo (COLMAP's when it has CUDA, else ours), fusion (COLMAP), meshing (COLMAP's
// when it has CGAL, else ours), source depth cache. Each stage records a fingerprint of
// its inputs and options in W/fvs/manifest.json and is skipped when that is unchanged and
// its outputs exist. Fingerprints chain (a stage's includes the one before it), so
// changing an early stage re-runs everything after it. Stages write into W/fvs/tmp/ and
// rename into place, so kill -9 at any point loses at most the stage that was running.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "colmap_ext/reconstruction.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/option_manager.h"
#include "fvs/exe/prepare_stages.h"
#include "fvs/util/error.h"
#include "fvs/util/manifest.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {
namespace fs = std::filesystem;

struct PrepareOptions {
  std::string image_path;
  std::string workspace_path;
  std::string matcher = "auto";  // auto | exhaustive | sequential
  std::string camera_model = "SIMPLE_RADIAL";
  bool single_camera = true;
  int max_image_size = 1600;            // SIFT and undistortion
  std::string stereo_backend = "auto";  // auto | colmap | builtin
  std::string mesher_backend = "auto";  // auto | colmap | builtin
  int stereo_max_image_size = 0;        // 0 = full undistorted size
  std::string holdout_images;  // file with one image name per line, or comma list
  int num_threads = -1;

  void Check() const {
    const std::string who = "colmap view_synthesis_prepare";
    Require(
        matcher == "auto" || matcher == "exhaustive" || matcher == "sequential", who,
        "--Matching.type must be auto, exhaustive or sequential, not '" + matcher + "'");
    Require(stereo_backend == "auto" || stereo_backend == "colmap" ||
                stereo_backend == "builtin",
            who, "--Stereo.backend must be auto, colmap or builtin");
    Require(mesher_backend == "auto" || mesher_backend == "colmap" ||
                mesher_backend == "builtin",
            who, "--Mesher.backend must be auto, colmap or builtin");
    Require(max_image_size > 0, who, "--max_image_size must be positive");
    Require(stereo_max_image_size >= 0, who, "--Stereo.max_image_size must be >= 0");
  }
};

int RunPrepare(int argc, char** argv) {
  PrepareOptions o;
  OptionManager options(
      "view_synthesis_prepare",
      "Photos to a ready view-synthesis scene: SfM, undistortion, dense "
      "stereo, fusion, meshing, source depth cache. Finished stages are "
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
  options.AddDefault("Mesher.backend", &o.mesher_backend,
                     "auto (COLMAP when it has CGAL), colmap, builtin");
  options.AddDefault(
      "holdout_images", &o.holdout_images,
      "images registered by SfM but kept out of stereo, fusion and meshing: "
      "a file with one name per line, or a comma-separated list");
  options.AddDefault("num_threads", &o.num_threads, "-1 = all cores");
  if (!options.Parse(argc, argv)) return 0;
  o.Check();

  PrepareContext context;
  context.image_path = fs::absolute(o.image_path).lexically_normal().string();
  context.workspace_path = fs::absolute(o.workspace_path).lexically_normal().string();
  context.matcher = o.matcher;
  context.camera_model = o.camera_model;
  context.single_camera = o.single_camera;
  context.max_image_size = o.max_image_size;
  context.stereo_backend = o.stereo_backend;
  context.mesher_backend = o.mesher_backend;
  context.stereo_max_image_size = o.stereo_max_image_size;
  context.holdout = ParseHoldoutList(o.holdout_images);
  context.num_threads = o.num_threads;
  RunPrepareStages(context);
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_prepare",
                     "photos -> ready scene (SfM, stereo, fusion, mesh, depth cache)",
                     RunPrepare);

}  // namespace fvs
