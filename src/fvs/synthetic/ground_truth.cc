#include "fvs/synthetic/ground_truth.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/camera_models.h"
#include "fvs/synthetic/random.h"
#include "fvs/synthetic/render.h"
#include "fvs/util/parallel.h"

namespace fvs {
namespace {

struct Observation {
  uint32_t view = 0;
  Eigen::Vector2d xy;
};

uint8_t ToByte(double value) {
  return static_cast<uint8_t>(std::lround(255.0 * std::clamp(value, 0.0, 1.0)));
}

}  // namespace

colmap::Reconstruction SyntheticGroundTruthModel(const SyntheticScene& scene) {
  const SyntheticSceneOptions& options = scene.options;
  colmap::Reconstruction model;
  colmap::Camera camera;
  camera.camera_id = 1;
  camera.model_id = colmap::kPinhole;
  camera.width = options.width;
  camera.height = options.height;
  const PinholeCamera& first = scene.cameras.at(0);
  camera.params = {first.fx, first.fy, first.cx, first.cy};
  model.cameras[1] = camera;
  for (int i = 0; i < scene.num_views(); ++i) {
    colmap::Image image;
    image.image_id = static_cast<uint32_t>(i + 1);
    image.camera_id = 1;
    image.name = scene.image_names[i];
    image.qvec = RotationToQuaternion(scene.cameras[i].R);
    image.tvec = scene.cameras[i].t;
    model.images[image.image_id] = image;
  }
  if (options.num_sparse_points == 0 || scene.mesh.faces.empty()) return model;

  // Candidates drawn sequentially (deterministic), area-weighted over the faces.
  std::vector<double> cumulative_area(scene.mesh.faces.size());
  double total = 0;
  for (size_t f = 0; f < scene.mesh.faces.size(); ++f) {
    const Eigen::Vector3i& face = scene.mesh.faces[f];
    const Eigen::Vector3d& a = scene.mesh.vertices[face[0]];
    total +=
        0.5 *
        (scene.mesh.vertices[face[1]] - a).cross(scene.mesh.vertices[face[2]] - a).norm();
    cumulative_area[f] = total;
  }
  const int num_candidates = 3 * options.num_sparse_points;
  synthetic::SceneRandom random(synthetic::Mix64(options.seed ^ 0x9017750ull));
  std::vector<Eigen::Vector3d> candidates(num_candidates);
  std::vector<int> candidate_face(num_candidates);
  for (int c = 0; c < num_candidates; ++c) {
    const double r = random.Uniform() * total;
    const int f = static_cast<int>(std::min<size_t>(
        std::upper_bound(cumulative_area.begin(), cumulative_area.end(), r) -
            cumulative_area.begin(),
        cumulative_area.size() - 1));
    double u = random.Uniform(), v = random.Uniform();
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    const Eigen::Vector3i& face = scene.mesh.faces[f];
    const Eigen::Vector3d& a = scene.mesh.vertices[face[0]];
    candidates[c] = a + u * (scene.mesh.vertices[face[1]] - a) +
                    v * (scene.mesh.vertices[face[2]] - a);
    candidate_face[c] = f;
  }

  // Visibility per candidate (independent, so parallel without changing the result).
  std::vector<std::vector<Observation>> observations(num_candidates);
  ParallelFor(0, num_candidates, [&](int64_t c) {
    const Eigen::Vector3d& p = candidates[c];
    for (int i = 0; i < scene.num_views(); ++i) {
      const PinholeCamera& cam = scene.cameras[i];
      const Eigen::Vector3d xc = cam.WorldToCamera(p);
      if (xc.z() < 1e-3) continue;
      const Eigen::Vector2d xy = cam.CameraToPixel(xc);
      if (!(xy.x() >= 0 && xy.y() >= 0 && xy.x() < cam.width && xy.y() < cam.height)) {
        continue;
      }
      const Eigen::Vector3d origin = cam.Center();
      synthetic::RayHit hit;
      // The ray reaches the point at t = 1; anything hit clearly before occludes it.
      if (scene.bvh.Intersect(origin, p - origin, 0.0, 1.0 - 1e-6, &hit) &&
          hit.face != candidate_face[c]) {
        continue;
      }
      observations[c].push_back({static_cast<uint32_t>(i + 1), xy});
    }
  });

  uint64_t next_id = 1;
  for (int c = 0;
       c < num_candidates && next_id <= static_cast<uint64_t>(options.num_sparse_points);
       ++c) {
    if (observations[c].size() < 2) continue;
    colmap::Point3D point;
    point.xyz = candidates[c];
    point.error = 0.0;  // exact projections
    const colmap::Image& viewer = model.images.at(observations[c][0].view);
    const Eigen::Vector3d direction = candidates[c] - viewer.ProjectionCenter();
    const Eigen::Vector3d radiance =
        ShadeSyntheticSurface(scene, candidate_face[c], candidates[c], direction);
    for (int k = 0; k < 3; ++k) point.color[k] = ToByte(SyntheticGamma(radiance[k]));
    for (const Observation& o : observations[c]) {
      colmap::Image& image = model.images.at(o.view);
      colmap::Point2D point2D;
      point2D.xy = o.xy;
      point2D.point3D_id = next_id;
      point.track.push_back({o.view, static_cast<uint32_t>(image.points2D.size())});
      image.points2D.push_back(point2D);
    }
    model.points3D[next_id] = point;
    ++next_id;
  }
  return model;
}

}  // namespace fvs
