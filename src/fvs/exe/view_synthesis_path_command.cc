// colmap view_synthesis_path --workspace_path W --output_path camera_path.json
//   keyframes: --keyframes name1,name2,... (registered images) | --keyframes_path in.json
//              (nerfstudio camera_path.json: its "keyframes", or its frames)
//              | neither: every registered image, sorted by name
//   --fps, --duration, --seconds_per_keyframe, --constant_speed, --smooth, the Ceres
//   weights (--Path.*), --images_txt out/images.txt (COLMAP text model of the frames)
// Writes the path and prints the optimisation's before/after jerk, keyframe error and
// coverage (fraction of each frame seen by its best K sources).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "fvs/exe/command_registry.h"
#include "fvs/path/camera_path.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/option_manager.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

void PrintStats(const char* label, const CameraPathStats& s, double fps) {
  std::printf("%-7s jerk %.4g /s^3 (rotation %.4g /s^3), keyframe error %.4g (%.3g deg)",
              label, s.jerk * fps * fps * fps, s.rotation_jerk * fps * fps * fps,
              s.keyframe_error, s.keyframe_angle_deg);
  if (s.min_coverage >= 0) {
    std::printf(", coverage mean %.1f%% min %.1f%%, %d frames under the threshold",
                100 * s.mean_coverage, 100 * s.min_coverage, s.num_low_coverage);
  }
  std::printf("\n");
}

// The keyframes of --keyframes_path, else the registered images named in --keyframes,
// else every registered image by name.
std::vector<CameraPathKeyframe> ChooseKeyframes(const Scene& scene,
                                                const std::string& keyframes,
                                                const std::string& keyframes_path) {
  if (!keyframes_path.empty()) {
    return ReadNerfstudioKeyframes(keyframes_path);
  }
  std::vector<std::string> names;
  for (const std::string& n : SplitString(keyframes, ",")) {
    if (!TrimString(n).empty()) names.push_back(TrimString(n));
  }
  if (names.empty()) {
    for (const SceneView& v : scene.views()) names.push_back(v.name);
    std::sort(names.begin(), names.end());
  }
  return KeyframesFromScene(scene, names);
}

int RunViewSynthesisPath(int argc, char** argv) {
  std::string workspace_path, output_path, keyframes, keyframes_path, images_txt;
  CameraPathOptions o;
  bool use_scene = true;
  OptionManager options(
      "view_synthesis_path",
      "Builds a smooth camera path (nerfstudio camera_path.json) through "
      "keyframes, optimised with Ceres.");
  options.AddRequired("workspace_path", &workspace_path, "prepared dense workspace");
  options.AddRequired("output_path", &output_path, "camera_path.json to write");
  options.AddDefault("keyframes", &keyframes,
                     "registered image names, comma separated (default: all, by name)");
  options.AddDefault("keyframes_path", &keyframes_path,
                     "nerfstudio camera_path.json whose keyframes (or frames) to use");
  options.AddDefault("images_txt", &images_txt,
                     "also write the frames as a COLMAP text model (images.txt + "
                     "cameras.txt + points3D.txt)");
  options.AddDefault("fps", &o.fps, "frames per second");
  options.AddDefault("duration", &o.duration_s,
                     "seconds (0: seconds_per_keyframe x (keyframes - 1))");
  options.AddDefault("seconds_per_keyframe", &o.seconds_per_keyframe,
                     "seconds between keyframes when --duration is 0");
  options.AddDefault("constant_speed", &o.constant_speed,
                     "frames equally spaced along the path");
  options.AddDefault("smooth", &o.smooth, "optimise the path with Ceres");
  options.AddDefault("width", &o.width, "frame width (0: the first keyframe's)");
  options.AddDefault("height", &o.height, "frame height (0: the first keyframe's)");
  options.AddDefault("use_scene", &use_scene,
                     "measure coverage and keep the camera where the sources see (loads "
                     "the mesh and source depths)");
  options.AddDefault("Path.jerk_weight", &o.jerk_weight, "weight of the jerk");
  options.AddDefault("Path.keyframe_weight", &o.keyframe_weight,
                     "weight of staying at the keyframes");
  options.AddDefault("Path.prior_weight", &o.prior_weight,
                     "weight of staying near the interpolated path");
  options.AddDefault("Path.look_weight", &o.look_weight,
                     "weight of looking towards the scene centre");
  options.AddDefault("Path.look_max_angle_deg", &o.look_max_angle_deg,
                     "angle from the scene centre beyond which the look term acts");
  options.AddDefault("Path.coverage_weight", &o.coverage_weight,
                     "pull of low-coverage frames towards the nearest registered camera");
  options.AddDefault("Path.coverage_threshold", &o.coverage_threshold,
                     "frames whose best K sources see less than this fraction are low");
  options.AddDefault("Path.coverage_num_sources", &o.coverage_num_sources, "K");
  options.AddDefault("Path.coverage_rounds", &o.coverage_rounds,
                     "measure / penalise / re-solve rounds");
  options.AddDefault("Path.max_iterations", &o.max_iterations,
                     "Ceres iterations per round");
  if (!options.Parse(argc, argv)) return 0;
  o.Check();
  Require(keyframes.empty() || keyframes_path.empty(), "colmap view_synthesis_path",
          "give --keyframes or --keyframes_path, not both");

  Timer timer;
  Scene scene = Scene::Load(workspace_path);
  const std::vector<CameraPathKeyframe> keys =
      ChooseKeyframes(scene, keyframes, keyframes_path);
  const double load_s = timer.Seconds();
  timer.Restart();
  const CameraPathResult r = ComputeCameraPath(keys, o, use_scene ? &scene : nullptr);
  const double path_s = timer.Seconds();
  const std::filesystem::path parent = std::filesystem::path(output_path).parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    Require(!ec, parent.string(), "cannot create the folder: " + ec.message());
  }
  WriteNerfstudioCameraPath(output_path, keys, r.frames, o);
  if (!images_txt.empty()) WriteTargetImagesTxt(images_txt, r.frames);

  std::printf(
      "%zu keyframes -> %zu frames (%d x %d, %.3g fps); scene loaded in %.2f s, "
      "path computed in %.2f s\n",
      keys.size(), r.frames.size(), r.frames.front().camera.width,
      r.frames.front().camera.height, o.fps, load_s, path_s);
  PrintStats("before", r.before, o.fps);
  PrintStats(o.smooth ? "after" : "(no smoothing)", r.after, o.fps);
  std::printf("wrote %s%s%s\n", output_path.c_str(), images_txt.empty() ? "" : " and ",
              images_txt.c_str());
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_path",
                     "smooth camera path through keyframes (camera_path.json)",
                     RunViewSynthesisPath);

}  // namespace fvs
