#include "fvs/mvs/stereo_test_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/geometry/look_at.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs::mvs {
namespace {

struct Quad {
  Eigen::Vector3d origin, axis_a, axis_b;  // unit axes
  double length_a, length_b;
  int texture_id;
  double brightness;
  Eigen::Vector3d Normal() const { return axis_a.cross(axis_b); }
};

std::vector<Quad> SceneQuads() {
  std::vector<Quad> quads;
  const Eigen::Vector3d ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  quads.push_back({{-4, 1, 1.5}, ex, ez, 8, 8, 0, 0.9});   // floor (y = 1, y is down)
  quads.push_back({{-4, -3, 7.5}, ex, ey, 8, 4, 1, 1.0});  // back wall (z = 7.5)
  // Box [-0.5, 0.7] x [0, 1] x [3.5, 4.5].
  quads.push_back({{-0.5, 0, 3.5}, ex, ey, 1.2, 1, 2, 1.0});  // front
  quads.push_back({{-0.5, 0, 4.5}, ex, ey, 1.2, 1, 3, 0.8});  // back
  quads.push_back({{-0.5, 0, 3.5}, ez, ey, 1, 1, 4, 0.85});   // left
  quads.push_back({{0.7, 0, 3.5}, ez, ey, 1, 1, 5, 0.75});    // right
  quads.push_back({{-0.5, 0, 3.5}, ex, ez, 1.2, 1, 6, 1.1});  // top
  // A slanted panel on the left.
  const Eigen::Vector3d slant = Eigen::Vector3d(1, 0, 1).normalized();
  quads.push_back({{-2.6, -0.8, 4.0}, slant, ey, 1.4, 1.8, 7, 0.95});
  return quads;
}

double Hash01(int64_t x, int64_t y, int64_t k) {
  uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ULL ^
               static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4FULL ^
               static_cast<uint64_t>(k) * 0x165667B19E3779F9ULL;
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDULL;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ULL;
  h ^= h >> 33;
  return (h >> 11) * (1.0 / 9007199254740992.0);
}

double ValueNoise(double s, double t, int64_t key) {
  const double fs = std::floor(s), ft = std::floor(t);
  const int64_t is = static_cast<int64_t>(fs), it = static_cast<int64_t>(ft);
  double a = s - fs, b = t - ft;
  a = a * a * (3 - 2 * a);
  b = b * b * (3 - 2 * b);
  const double v00 = Hash01(is, it, key), v10 = Hash01(is + 1, it, key);
  const double v01 = Hash01(is, it + 1, key), v11 = Hash01(is + 1, it + 1, key);
  return (v00 * (1 - a) + v10 * a) * (1 - b) + (v01 * (1 - a) + v11 * a) * b;
}

// Several octaves so that the surfaces are textured at every image size we render.
double Texture(const Quad& q, double s, double t, uint64_t seed, double tile) {
  if (tile > 0) {
    const double grout = 0.1 * tile;
    const bool on_grout = std::fmod(s, tile) < grout || std::fmod(t, tile) < grout;
    if (!on_grout) return 0.6 * q.brightness;
  }
  const int64_t key = static_cast<int64_t>(seed) * 131 + q.texture_id * 17;
  const double v = 0.45 * ValueNoise(s / 0.03, t / 0.03, key) +
                   0.35 * ValueNoise(s / 0.08, t / 0.08, key + 1) +
                   0.20 * ValueNoise(s / 0.25, t / 0.25, key + 2);
  return std::clamp(0.1 + 0.8 * v * q.brightness, 0.0, 1.0);
}

// Nearest surface along a ray: parameter along `dir` (infinity when none) and the grey
// value.
double CastRay(const std::vector<Quad>& quads, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& dir, uint64_t seed, double tile, double* grey) {
  double best = std::numeric_limits<double>::infinity();
  for (const Quad& q : quads) {
    const Eigen::Vector3d n = q.Normal();
    const double denom = n.dot(dir);
    if (std::abs(denom) < 1e-12) continue;
    const double lambda = n.dot(q.origin - origin) / denom;
    if (!(lambda > 1e-9) || lambda >= best) continue;
    const Eigen::Vector3d p = origin + lambda * dir - q.origin;
    const double s = q.axis_a.dot(p), t = q.axis_b.dot(p);
    if (s < 0 || t < 0 || s > q.length_a || t > q.length_b) continue;
    best = lambda;
    if (grey) *grey = Texture(q, s, t, seed, tile);
  }
  return best;
}

// Image y along world +y: up = -y.
PinholeCamera LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                     int width, int height) {
  return LookAtCamera(center, target, width, height, 0.9 * width,
                      -Eigen::Vector3d::UnitY());
}

}  // namespace

AnalyticScene RenderAnalyticScene(const AnalyticSceneOptions& options) {
  Require(options.num_views >= 2, "AnalyticScene", "need at least 2 views");
  Require(options.width >= 8 && options.height >= 8, "AnalyticScene", "image too small");
  Require(options.supersampling >= 1, "AnalyticScene", "supersampling must be >= 1");
  Require(options.tile_size >= 0 && std::isfinite(options.tile_size), "AnalyticScene",
          "tile_size must be >= 0");
  const std::vector<Quad> quads = SceneQuads();
  AnalyticScene scene;
  const Eigen::Vector3d target(0.1, 0.3, 4.5);
  for (int v = 0; v < options.num_views; ++v) {
    const double f =
        options.num_views == 1 ? 0.5 : static_cast<double>(v) / (options.num_views - 1);
    const Eigen::Vector3d center(-0.9 + 1.8 * f, -0.35 + 0.15 * std::sin(6.0 * f),
                                 0.2 * std::cos(3.0 * f));
    const PinholeCamera cam = LookAt(center, target, options.width, options.height);
    char name[32];
    std::snprintf(name, sizeof(name), "view_%03d.png", v);
    scene.names.push_back(name);
    scene.cameras.push_back(cam);
    Image image(cam.width, cam.height, 3), depth(cam.width, cam.height, 1);
    const int ss = options.supersampling;
    const Eigen::Vector3d c = cam.Center();
    ParallelFor(0, cam.height, [&](int64_t y) {
      for (int x = 0; x < cam.width; ++x) {
        const Eigen::Vector3d d0 =
            cam.R.transpose() * cam.PixelToCamera(x + 0.5, y + 0.5, 1.0);
        const double lambda = CastRay(quads, c, d0, options.seed, 0, nullptr);
        // d0 has camera-frame z = 1, so the ray parameter is the depth.
        depth.at(x, y) = std::isfinite(lambda) ? static_cast<float>(lambda) : 0.f;
        double sum = 0;
        for (int sy = 0; sy < ss; ++sy) {
          for (int sx = 0; sx < ss; ++sx) {
            const Eigen::Vector3d d =
                cam.R.transpose() *
                cam.PixelToCamera(x + (sx + 0.5) / ss, y + (sy + 0.5) / ss, 1.0);
            double g = 0;
            if (std::isfinite(CastRay(quads, c, d, options.seed, options.tile_size, &g))) sum += g;
          }
        }
        const float g = static_cast<float>(sum / (ss * ss));
        for (int ch = 0; ch < 3; ++ch) image.at(x, y, ch) = g;
      }
    });
    scene.images.push_back(std::move(image));
    scene.depths.push_back(std::move(depth));
  }
  // Sparse points: surface samples with their visibility, as SfM would triangulate them.
  double total_area = 0;
  for (const Quad& q : quads) total_area += q.length_a * q.length_b;
  for (int p = 0; p < options.num_sparse_points; ++p) {
    double pick = Hash01(p, 1, options.seed) * total_area;
    const Quad* quad = &quads.back();
    for (const Quad& q : quads) {
      if (pick < q.length_a * q.length_b) {
        quad = &q;
        break;
      }
      pick -= q.length_a * q.length_b;
    }
    const Eigen::Vector3d xyz =
        quad->origin + Hash01(p, 2, options.seed) * quad->length_a * quad->axis_a +
        Hash01(p, 3, options.seed) * quad->length_b * quad->axis_b;
    AnalyticScene::Track track;
    track.xyz = xyz;
    for (int v = 0; v < options.num_views; ++v) {
      const PinholeCamera& cam = scene.cameras[v];
      const Eigen::Vector3d xc = cam.WorldToCamera(xyz);
      if (xc.z() <= 0) continue;
      const Eigen::Vector2d uv = cam.CameraToPixel(xc);
      const int ix = static_cast<int>(std::floor(uv.x())),
                iy = static_cast<int>(std::floor(uv.y()));
      if (ix < 0 || iy < 0 || ix >= cam.width || iy >= cam.height) continue;
      const double gt = scene.depths[v].at(ix, iy);
      if (gt <= 0 || std::abs(gt - xc.z()) > 0.02 * xc.z()) continue;  // occluded
      track.observations.push_back({v, uv});
    }
    if (track.observations.size() >= 2) scene.tracks.push_back(std::move(track));
  }
  return scene;
}

void WriteAnalyticWorkspace(const AnalyticScene& scene, const std::string& dir) {
  colmap::DenseWorkspace ws(dir);
  colmap::CreateDirectories(ws.ImagesDir());
  colmap::CreateDirectories(ws.SparseDir());
  colmap::CreateDirectories(dir + "/ground_truth");
  colmap::Reconstruction rec;
  for (size_t v = 0; v < scene.cameras.size(); ++v) {
    const PinholeCamera& c = scene.cameras[v];
    colmap::Camera camera;
    camera.camera_id = static_cast<uint32_t>(v + 1);
    camera.model_id = colmap::kPinhole;
    camera.width = c.width;
    camera.height = c.height;
    camera.params = {c.fx, c.fy, c.cx, c.cy};
    rec.cameras[camera.camera_id] = camera;
    colmap::Image image;
    image.image_id = static_cast<uint32_t>(v + 1);
    image.camera_id = camera.camera_id;
    image.name = scene.names[v];
    image.qvec = RotationToQuaternion(c.R);
    image.tvec = c.t;
    rec.images[image.image_id] = image;
    colmap::WriteImage(ws.ImagePath(scene.names[v]), scene.images[v]);
    colmap::WriteColmapArray(dir + "/ground_truth/" + scene.names[v] + ".bin",
                             scene.depths[v]);
  }
  uint64_t point_id = 1;
  for (const AnalyticScene::Track& t : scene.tracks) {
    colmap::Point3D point;
    point.xyz = t.xyz;
    point.color = {128, 128, 128};
    point.error = 0.5;
    for (const auto& [view, uv] : t.observations) {
      colmap::Image& image = rec.images[static_cast<uint32_t>(view + 1)];
      colmap::Point2D p2d;
      p2d.xy = uv;
      p2d.point3D_id = point_id;
      point.track.push_back(
          {image.image_id, static_cast<uint32_t>(image.points2D.size())});
      image.points2D.push_back(p2d);
    }
    rec.points3D[point_id++] = point;
  }
  colmap::WriteSparseModelBinary(ws.SparseDir(), rec);
}

}  // namespace fvs::mvs
