#include "fvs/synthetic/render.h"

#include <algorithm>
#include <cmath>

#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {

double SyntheticGamma(double linear) {
  return std::pow(std::clamp(linear, 0.0, 1.0), 1.0 / 2.2);
}

Eigen::Vector3d ShadeSyntheticSurface(const SyntheticScene& scene, int face,
                                      const Eigen::Vector3d& point,
                                      const Eigen::Vector3d& view_direction) {
  Eigen::Vector3d n = scene.bvh.FaceNormal(face);
  if (n.dot(view_direction) > 0) n = -n;  // the side the camera sees
  const double shading = 0.3 + 0.6 * std::max(0.0, n.dot(scene.key_light)) +
                         0.25 * std::max(0.0, n.dot(scene.fill_light));
  return scene.materials[scene.face_material[face]].Albedo(point) * shading;
}

void RenderSyntheticView(const SyntheticScene& scene, const PinholeCamera& camera,
                         Image* color, Image* depth, Image* normals, int supersampling,
                         int num_threads) {
  Require(camera.IsValid(), "RenderSyntheticView", "invalid camera");
  Require(static_cast<int>(scene.face_material.size()) == scene.bvh.num_triangles(),
          "RenderSyntheticView",
          "scene BVH does not match its mesh (use BuildSyntheticScene)");
  if (supersampling <= 0) supersampling = scene.options.supersampling;
  Require(supersampling <= 16, "RenderSyntheticView", "supersampling must be <= 16");
  const int w = camera.width, h = camera.height;
  if (color) *color = Image(w, h, 3);
  if (depth) *depth = Image(w, h, 1);
  if (normals) *normals = Image(w, h, 3);

  const Eigen::Vector3d origin = camera.Center();
  const Eigen::Matrix3d camera_to_world = camera.R.transpose();
  // The ray through pixel (u, v) has camera-frame direction ((u-cx)/fx, (v-cy)/fy, 1):
  // its hit parameter t is exactly the camera-frame depth.
  auto ray = [&](double u, double v) {
    return Eigen::Vector3d(camera_to_world * Eigen::Vector3d((u - camera.cx) / camera.fx,
                                                             (v - camera.cy) / camera.fy,
                                                             1.0));
  };
  constexpr double kMaxDepth = 1e12;

  ParallelFor(
      0, h,
      [&](int64_t y64) {
        const int y = static_cast<int>(y64);
        synthetic::RayHit hit;
        for (int x = 0; x < w; ++x) {
          if (depth || normals) {
            const Eigen::Vector3d d = ray(x + 0.5, y + 0.5);
            if (scene.bvh.Intersect(origin, d, 0.0, kMaxDepth, &hit)) {
              if (depth) depth->at(x, y) = static_cast<float>(hit.t);
              if (normals) {
                Eigen::Vector3d n = camera.R * scene.bvh.FaceNormal(hit.face);
                if (n.dot(camera.R * d) > 0) n = -n;
                for (int c = 0; c < 3; ++c)
                  normals->at(x, y, c) = static_cast<float>(n[c]);
              }
            }
          }
          if (color) {
            Eigen::Vector3d sum = Eigen::Vector3d::Zero();
            for (int j = 0; j < supersampling; ++j) {
              for (int i = 0; i < supersampling; ++i) {
                const Eigen::Vector3d d =
                    ray(x + (i + 0.5) / supersampling, y + (j + 0.5) / supersampling);
                if (scene.bvh.Intersect(origin, d, 0.0, kMaxDepth, &hit)) {
                  sum += ShadeSyntheticSurface(scene, hit.face, origin + hit.t * d, d)
                             .cwiseMin(1.0);
                }
              }
            }
            sum /= static_cast<double>(supersampling * supersampling);
            for (int c = 0; c < 3; ++c) {
              color->at(x, y, c) = static_cast<float>(SyntheticGamma(sum[c]));
            }
          }
        }
      },
      num_threads);
}

}  // namespace fvs
