// Target cameras for `colmap view_synthesis`, in WORLD coordinates (the caller moves them
// into the scene frame with Scene::ToSceneCamera):
//   - COLMAP images.txt (+ cameras.txt beside it, or the workspace's camera for a
//   camera_id
//     it has), pinhole models only (targets are rendered undistorted);
//   - nerfstudio camera_path.json: "camera_path": [{"camera_to_world": 16 numbers,
//   row-major
//     4x4, OpenGL axes (x right, y up, z back), "fov": vertical degrees, "aspect"}],
//     "render_width", "render_height". Poses are taken as given, in the workspace's frame
//     (nerfstudio's own dataparser transform, if any, is not undone);
//   - an orbit around the scene centre, or an interpolation between registered cameras.
#pragma once

#include <string>
#include <vector>

#include "fvs/geometry/camera.h"

namespace fvs {

class Scene;

struct TargetCamera {
  std::string name;  // output file stem
  PinholeCamera camera;
  std::string image_name;  // images.txt NAME (empty for generated paths)
};

// Every returned camera IsValid(); bad files throw fvs::Error naming the file and line.
std::vector<TargetCamera> ReadTargetImagesTxt(const std::string& path,
                                              const Scene& scene);
std::vector<TargetCamera> ReadNerfstudioCameraPath(const std::string& path);
// num_views cameras on a circle around the scene centre (least-squares point nearest to
// all optical axes, or the mesh centroid when the axes are near parallel), at the
// cameras' mean height and horizontal distance, looking at the centre, with the
// intrinsics of the first view. Frames are named frame_%05d.
std::vector<TargetCamera> OrbitTargets(const Scene& scene, int num_views);
// num_per_segment cameras between consecutive registered views (by name): rotation slerp,
// linear centre and intrinsics; the last view closes the path.
std::vector<TargetCamera> InterpolateTargets(const Scene& scene, int num_per_segment);

// The file stem of the index-th frame of a generated path: frame_00000, frame_00001, ...
std::string FrameName(int index);

// Output size: width/height > 0 set it (one of them alone keeps the aspect ratio), then
// scale multiplies. Throws fvs::Error for a non-positive result.
PinholeCamera ResizeTarget(const PinholeCamera& camera, int width, int height,
                           double scale);

// A camera-to-world matrix in OpenGL axes -> our world-to-camera (x right, y down, z
// forward).
void OpenGlCameraToWorldToPose(const Eigen::Matrix4d& c2w, Eigen::Matrix3d* R,
                               Eigen::Vector3d* t);

}  // namespace fvs
