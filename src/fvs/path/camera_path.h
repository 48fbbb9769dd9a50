// Camera paths for fly-through videos: keyframes (registered cameras by name, a
// nerfstudio camera_path.json, or GUI keyframes) -> frames at a frame rate, interpolated
// smoothly (cubic Catmull-Rom in position, squad in rotation, linear in vertical field of
// view), optionally at constant speed along the arc, then optimised with Ceres:
//
//   minimise  sum |third difference of position and rotation|^2          (jerk)
//           + sum over keyframes |frame pose - keyframe pose|^2          (stay near keys)
//           + weak |frame pose - interpolated pose|^2                    (well posed)
//           + look: hinge on the angle between the view axis and the scene centre
//           + coverage: frames whose overlap with the best K sources falls below a
//             threshold are pulled towards the nearest registered camera (outer loop:
//             the overlap is measured by rendering, which is not differentiable)
//
// Every pose is in the WORLD frame (what images.txt and camera_path.json hold); the
// scene, when given, is only used to measure coverage and find the scene centre. Frames
// are named frame_00000, frame_00001, ...; every frame has square pixels and a centred
// principal point (what a nerfstudio path can hold).
#pragma once

#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/render/targets.h"

namespace fvs {

class Scene;

struct CameraPathKeyframe {
  std::string name;      // registered image name, or any label
  PinholeCamera camera;  // WORLD frame
};

struct CameraPathOptions {
  double fps = 30;
  // Length of the video; 0: seconds_per_keyframe * (keys - 1).
  double duration_s = 0;
  double seconds_per_keyframe = 2;
  // Frames equally spaced along the arc (position plus rotation, see
  // rotation_arc_scale) rather than equally spaced in keyframe time.
  bool constant_speed = true;
  // Output size; 0: the first keyframe's (one of them alone keeps its aspect ratio).
  int width = 0;
  int height = 0;

  // Ceres smoothing.
  bool smooth = true;
  double jerk_weight = 1.0;         // on third differences (per frame, path scale units)
  double keyframe_weight = 1000.0;  // frame at a keyframe's time vs that keyframe
  double prior_weight = 0.01;       // every frame vs its interpolated pose
  double look_weight = 1.0;         // hinge on the look direction (needs a scene)
  double look_max_angle_deg = 60;   // allowed angle between view axis and scene centre
  double coverage_weight = 1.0;     // pull of low-coverage frames towards a source camera
  double coverage_threshold = 0.5;  // fraction of target pixels seen by the best K
  int coverage_num_sources = 5;     // K
  int coverage_width = 64;          // coverage is measured at this width (cheap)
  int coverage_rounds = 3;          // outer rounds (measure, penalise, re-solve)
  int max_iterations = 200;         // Ceres iterations per round
  // One radian of rotation counts as this share of the keyframes' extent in the arc
  // length (constant speed), so that a pure rotation is also paced evenly.
  double rotation_arc_scale = 0.25;
  void Check() const;
};

// Figures of one path, for the command's before/after report.
struct CameraPathStats {
  double jerk = 0;                // RMS third difference of the centres per frame^3
  double rotation_jerk = 0;       // RMS third difference of the quaternions
  double keyframe_error = 0;      // max distance of a keyframe to its frame's centre
  double keyframe_angle_deg = 0;  // max angle between keyframe and its frame
  double min_coverage = -1;       // -1 when no scene was given
  double mean_coverage = -1;
  int num_low_coverage = 0;  // frames under coverage_threshold
};

struct CameraPathResult {
  std::vector<TargetCamera> frames;
  std::vector<double> keyframe_frame;  // fractional frame index of each keyframe
  std::vector<double> coverage;        // per frame (empty without a scene)
  CameraPathStats before;              // the interpolated path
  CameraPathStats after;               // after smoothing (== before when !smooth)
};

// Frames (world frame, named frame_00000...) through the keyframes; 1 keyframe or
// repeated poses allowed. Throws fvs::Error for no keyframes or invalid cameras.
std::vector<TargetCamera> InterpolateCameraPath(
    const std::vector<CameraPathKeyframe>& keys, const CameraPathOptions& options,
    const Scene* scene = nullptr);
// The same with the figures before and after smoothing.
CameraPathResult ComputeCameraPath(const std::vector<CameraPathKeyframe>& keys,
                                   const CameraPathOptions& options,
                                   const Scene* scene = nullptr);

// Fraction of a world-frame target's pixels seen by at least one of its best K sources,
// measured at `width` pixels wide (0: full size). 0 for a camera that sees no surface.
double TargetCoverage(const Scene& scene, const PinholeCamera& world_camera, int k,
                      int width);

// nerfstudio camera_path.json with "keyframes" and "camera_path" (frames),
// render_width/height, fps, seconds; atomic. Reading it back with
// ReadNerfstudioCameraPath gives the same frames.
void WriteNerfstudioCameraPath(const std::string& path,
                               const std::vector<CameraPathKeyframe>& keys,
                               const std::vector<TargetCamera>& frames,
                               const CameraPathOptions& options);
// The "keyframes" list (our "camera_to_world" row-major, or nerfstudio's "matrix": a
// list is row-major as the viser viewer writes it, a string column-major as the legacy
// three.js viewer did), or the "camera_path" frames if there are no keyframes.
std::vector<CameraPathKeyframe> ReadNerfstudioKeyframes(const std::string& path);
// Registered cameras of the scene by image name, in the given order, in the WORLD frame.
std::vector<CameraPathKeyframe> KeyframesFromScene(const Scene& scene,
                                                   const std::vector<std::string>& names);

// COLMAP images.txt + cameras.txt (PINHOLE, one per distinct intrinsics) + an empty
// points3D.txt beside it, readable by ReadTargetImagesTxt and by `colmap
// model_converter`. Image names are <frame name>.png. Atomic per file.
void WriteTargetImagesTxt(const std::string& path,
                          const std::vector<TargetCamera>& frames);

// Path figures without a scene (coverage left at -1).
CameraPathStats MeasureCameraPath(const std::vector<TargetCamera>& frames,
                                  const std::vector<CameraPathKeyframe>& keys,
                                  const std::vector<double>& keyframe_frame);

}  // namespace fvs
