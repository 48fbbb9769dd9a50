// In-memory tests of the synthetic scene: options, determinism, cameras, exact depth and
// normals (against a brute-force ray caster written here, independent of the BVH), and
// texture richness. Small images keep it fast.
#include "fvs/synthetic/synthetic_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "fvs/synthetic/render.h"
#include "fvs/util/error.h"

namespace fvs {
namespace {

SyntheticSceneOptions SmallOptions(uint64_t seed, int width = 96, int height = 72) {
  SyntheticSceneOptions options;
  options.seed = seed;
  options.num_views = 12;
  options.width = width;
  options.height = height;
  return options;
}

// Nearest hit of a ray over every triangle (no acceleration structure).
bool BruteForceHit(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& dir, double* t_out, int* face_out) {
  double best = std::numeric_limits<double>::max();
  int best_face = -1;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d& a = mesh.vertices[mesh.faces[f][0]];
    const Eigen::Vector3d& b = mesh.vertices[mesh.faces[f][1]];
    const Eigen::Vector3d& c = mesh.vertices[mesh.faces[f][2]];
    // Solve origin + t dir = a + u (b - a) + v (c - a) directly (Cramer's rule).
    Eigen::Matrix3d m;
    m << -dir, b - a, c - a;
    const double det = m.determinant();
    if (std::abs(det) < 1e-300) continue;
    const Eigen::Vector3d x = m.inverse() * (origin - a);
    if (x[1] < -1e-9 || x[2] < -1e-9 || x[1] + x[2] > 1 + 1e-9 || x[0] <= 0) continue;
    if (x[0] < best) {
      best = x[0];
      best_face = static_cast<int>(f);
    }
  }
  *t_out = best;
  *face_out = best_face;
  return best_face >= 0;
}

TEST(SyntheticScene, OptionsCheckRejectsBadValues) {
  SyntheticSceneOptions options;
  EXPECT_NO_THROW(options.Check());
  options.num_views = 0;
  EXPECT_THROW(options.Check(), Error);
  options = SyntheticSceneOptions();
  options.width = 4;
  EXPECT_THROW(BuildSyntheticScene(options), Error);
  options = SyntheticSceneOptions();
  options.supersampling = 0;
  EXPECT_THROW(options.Check(), Error);
  options = SyntheticSceneOptions();
  options.focal_factor = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(options.Check(), Error);
}

TEST(SyntheticScene, DeterministicForASeedAndThreadCount) {
  const SyntheticScene a = BuildSyntheticScene(SmallOptions(7));
  const SyntheticScene b = BuildSyntheticScene(SmallOptions(7));
  const SyntheticScene c = BuildSyntheticScene(SmallOptions(8));
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  for (size_t i = 0; i < a.mesh.vertices.size(); ++i) {
    ASSERT_EQ(a.mesh.vertices[i], b.mesh.vertices[i]);
  }
  Image color_a, depth_a, color_b, depth_b, color_c;
  RenderSyntheticView(a, a.cameras[5], &color_a, &depth_a, nullptr, 0, /*threads=*/1);
  RenderSyntheticView(b, b.cameras[5], &color_b, &depth_b, nullptr, 0, /*threads=*/3);
  EXPECT_TRUE(color_a.data == color_b.data);
  EXPECT_TRUE(depth_a.data == depth_b.data);
  RenderSyntheticView(c, c.cameras[5], &color_c, nullptr, nullptr);
  EXPECT_FALSE(color_a.data == color_c.data);
  EXPECT_NE(a.cameras[0].t, c.cameras[0].t);
}

TEST(SyntheticScene, CamerasFollowASmoothPathInsideTheRoom) {
  const SyntheticScene scene = BuildSyntheticScene(SyntheticSceneOptions());
  ASSERT_EQ(scene.num_views(), 40);
  ASSERT_EQ(scene.image_names.size(), 40u);
  EXPECT_EQ(scene.image_names[0], "frame_0000.png");
  EXPECT_EQ(scene.image_names[39], "frame_0039.png");
  EXPECT_EQ(scene.mesh.colors.size(), scene.mesh.vertices.size());
  EXPECT_EQ(scene.face_material.size(), scene.mesh.faces.size());
  EXPECT_GT(scene.scene_size, 8.0);
  for (int i = 0; i < scene.num_views(); ++i) {
    const PinholeCamera& camera = scene.cameras[i];
    ASSERT_TRUE(camera.IsValid());
    EXPECT_EQ(camera.width, 640);
    EXPECT_EQ(camera.height, 480);
    EXPECT_NEAR(camera.fx, 0.85 * 640, 1e-9);
    EXPECT_EQ(camera.cx, 320);
    EXPECT_TRUE(scene.bounds.contains(camera.Center()));
    if (i == 0) continue;
    const PinholeCamera& previous = scene.cameras[i - 1];
    const double baseline = (camera.Center() - previous.Center()).norm();
    const double angle =
        Eigen::AngleAxisd(camera.R * previous.R.transpose()).angle() * 180 / M_PI;
    EXPECT_GT(baseline, 0.1) << i;  // enough to triangulate
    EXPECT_LT(baseline, 0.6) << i;  // strong overlap
    EXPECT_LT(angle, 12.0) << i;
  }
}

TEST(SyntheticScene, DepthIsExactAndNormalsMatchTheMesh) {
  const SyntheticScene scene = BuildSyntheticScene(SmallOptions(1, 40, 30));
  for (int view : {0, 7}) {
    const PinholeCamera& camera = scene.cameras[view];
    Image depth, normals;
    RenderSyntheticView(scene, camera, nullptr, &depth, &normals);
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        const double z = depth.at(x, y);
        ASSERT_GT(z, 0.0) << "hole at " << x << "," << y;  // the room is closed
        const Eigen::Vector3d dir =
            camera.R.transpose() * camera.PixelToCamera(x + 0.5, y + 0.5, 1.0);
        double t;
        int face;
        ASSERT_TRUE(BruteForceHit(scene.mesh, camera.Center(), dir, &t, &face));
        // The BVH hit and the brute-force one agree (depth is camera-frame z = t here).
        EXPECT_NEAR(z, t, 1e-6 * t) << x << "," << y;
        // The unprojected pixel lies on the plane of the face it hit.
        const Eigen::Vector3d p = camera.Unproject(x + 0.5, y + 0.5, z);
        const Eigen::Vector3i& f = scene.mesh.faces[face];
        const Eigen::Vector3d a = scene.mesh.vertices[f[0]];
        const Eigen::Vector3d n = (scene.mesh.vertices[f[1]] - a)
                                      .cross(scene.mesh.vertices[f[2]] - a)
                                      .normalized();
        EXPECT_LT(std::abs(n.dot(p - a)), 1e-6 * z);
        // Normal map: unit, camera frame, towards the camera, parallel to the face
        // normal.
        const Eigen::Vector3d nc(normals.at(x, y, 0), normals.at(x, y, 1),
                                 normals.at(x, y, 2));
        EXPECT_NEAR(nc.norm(), 1.0, 1e-5);
        EXPECT_LT(nc.dot(camera.PixelToCamera(x + 0.5, y + 0.5, 1.0)), 0.0);
        EXPECT_GT(std::abs(nc.dot(camera.R * n)), 1 - 1e-5);
      }
    }
  }
}

TEST(SyntheticScene, NoHolesAndEveryViewSeesObjects) {
  const SyntheticScene scene = BuildSyntheticScene(SmallOptions(2, 160, 120));
  for (int view = 0; view < scene.num_views(); ++view) {
    const PinholeCamera& camera = scene.cameras[view];
    Image depth;
    RenderSyntheticView(scene, camera, nullptr, &depth, nullptr);
    int objects = 0;
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        ASSERT_GT(depth.at(x, y), 0.0f);
        ASSERT_TRUE(std::isfinite(depth.at(x, y)));
        synthetic::RayHit hit;
        const Eigen::Vector3d dir =
            camera.R.transpose() * camera.PixelToCamera(x + 0.5, y + 0.5, 1.0);
        ASSERT_TRUE(scene.bvh.Intersect(camera.Center(), dir, 0, 1e9, &hit));
        const std::string& name = scene.primitive_names[scene.face_primitive[hit.face]];
        if (name.rfind("room.", 0) != 0) ++objects;
      }
    }
    // Not a blank wall: objects cover a good part of every view...
    EXPECT_GT(objects, camera.width * camera.height / 10) << view;
    // ...and no camera stands in front of a surface closer than half a metre.
    EXPECT_GT(*std::min_element(depth.data.begin(), depth.data.end()), 0.5f) << view;
  }
}

// Fraction of 16x16 blocks whose grey standard deviation exceeds `threshold`.
double TexturedBlockFraction(const Image& color, double threshold) {
  int textured = 0, total = 0;
  for (int by = 0; by + 16 <= color.height; by += 16) {
    for (int bx = 0; bx + 16 <= color.width; bx += 16) {
      double sum = 0, sum2 = 0;
      for (int y = by; y < by + 16; ++y) {
        for (int x = bx; x < bx + 16; ++x) {
          const double g =
              (color.at(x, y, 0) + color.at(x, y, 1) + color.at(x, y, 2)) / 3.0;
          sum += g;
          sum2 += g * g;
        }
      }
      const double mean = sum / 256, var = sum2 / 256 - mean * mean;
      textured += std::sqrt(std::max(var, 0.0)) > threshold;
      ++total;
    }
  }
  return static_cast<double>(textured) / total;
}

TEST(SyntheticScene, TextureIsRichEverywhere) {
  SyntheticSceneOptions options;
  options.num_views = 12;
  const SyntheticScene scene = BuildSyntheticScene(options);
  for (int view : {0, 11}) {
    Image color;
    RenderSyntheticView(scene, scene.cameras[view], &color, nullptr, nullptr);
    for (float v : color.data) ASSERT_TRUE(v >= 0.0f && v <= 1.0f);
    // No flat regions at SIFT's scales: nearly every 16x16 block varies by several grey
    // levels, and most by more than five.
    EXPECT_GT(TexturedBlockFraction(color, 0.01), 0.98) << "view " << view;
    EXPECT_GT(TexturedBlockFraction(color, 0.02), 0.9) << "view " << view;
    // A flat image would fail this (the test can fail).
    Image flat = color;
    std::fill(flat.data.begin(), flat.data.end(), 0.5f);
    EXPECT_EQ(TexturedBlockFraction(flat, 0.02), 0.0);
  }
}

}  // namespace
}  // namespace fvs
