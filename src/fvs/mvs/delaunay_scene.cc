#include "fvs/mvs/delaunay_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <unordered_map>

#include "fvs/geometry/look_at.h"
#include "fvs/util/parallel.h"

namespace fvs::mvs {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double BoxSignedDistance(const ScenePrimitive& box, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = (p - box.centre).cwiseAbs() - box.half_size;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return outside + inside;
}

// First boundary crossing of a box along the ray (slab method).
double BoxHit(const ScenePrimitive& box, const Eigen::Vector3d& o,
              const Eigen::Vector3d& d, double min_t) {
  double t0 = -kInf, t1 = kInf;
  for (int a = 0; a < 3; ++a) {
    const double lo = box.centre[a] - box.half_size[a];
    const double hi = box.centre[a] + box.half_size[a];
    if (d[a] == 0) {
      if (o[a] < lo || o[a] > hi) return kInf;
      continue;
    }
    double ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return kInf;
  if (t0 > min_t) return t0;
  if (t1 > min_t) return t1;
  return kInf;
}

double SphereHit(const ScenePrimitive& s, const Eigen::Vector3d& o,
                 const Eigen::Vector3d& d, double min_t) {
  const Eigen::Vector3d oc = o - s.centre;
  const double a = d.squaredNorm();
  const double b = oc.dot(d);
  const double c = oc.squaredNorm() - s.radius * s.radius;
  const double disc = b * b - a * c;
  if (disc < 0) return kInf;
  const double root = std::sqrt(disc);
  const double ta = (-b - root) / a, tb = (-b + root) / a;
  if (ta > min_t) return ta;
  if (tb > min_t) return tb;
  return kInf;
}

// Closest point on triangle (Ericson, Real-Time Collision Detection 5.1.5).
Eigen::Vector3d ClosestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return a;  // degenerate triangle
  return a + ab * (vb / denom) + ac * (vc / denom);
}

double Percentile90(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t k = static_cast<size_t>(0.9 * (v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

}  // namespace

double MeshingScene::DistanceToSurface(const Eigen::Vector3d& p) const {
  double best = kInf;
  for (const auto& prim : primitives) {
    const double d = prim.type == ScenePrimitive::Type::kBox
                         ? std::abs(BoxSignedDistance(prim, p))
                         : std::abs((p - prim.centre).norm() - prim.radius);
    best = std::min(best, d);
  }
  return best;
}

Eigen::Vector3d MeshingScene::NormalAt(const Eigen::Vector3d& p) const {
  double best = kInf;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  for (const auto& prim : primitives) {
    Eigen::Vector3d n;
    double d;
    if (prim.type == ScenePrimitive::Type::kBox) {
      d = std::abs(BoxSignedDistance(prim, p));
      const Eigen::Vector3d q = (p - prim.centre).cwiseAbs() - prim.half_size;
      int axis = 0;
      q.maxCoeff(&axis);
      n = Eigen::Vector3d::Zero();
      n[axis] = p[axis] > prim.centre[axis] ? 1 : -1;
    } else {
      d = std::abs((p - prim.centre).norm() - prim.radius);
      n = (p - prim.centre).normalized();
    }
    if (d < best) best = d, normal = prim.hollow ? Eigen::Vector3d(-n) : n;
  }
  return normal;
}

bool MeshingScene::IsFree(const Eigen::Vector3d& p) const {
  for (const auto& prim : primitives) {
    const double sd = prim.type == ScenePrimitive::Type::kBox
                          ? BoxSignedDistance(prim, p)
                          : (p - prim.centre).norm() - prim.radius;
    if (prim.hollow ? sd > 0 : sd < 0) return false;
  }
  return true;
}

double MeshingScene::FirstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                              double min_t) const {
  double best = kInf;
  for (const auto& prim : primitives) {
    best = std::min(best, prim.type == ScenePrimitive::Type::kBox
                              ? BoxHit(prim, origin, dir, min_t)
                              : SphereHit(prim, origin, dir, min_t));
  }
  return best;
}

bool MeshingScene::Sees(size_t k, const Eigen::Vector3d& p) const {
  const PinholeCamera& camera = cameras[k];
  const Eigen::Vector3d pc = camera.WorldToCamera(p);
  if (pc.z() <= 1e-6) return false;
  const Eigen::Vector2d px = camera.CameraToPixel(pc);
  if (px.x() < 0 || px.y() < 0 || px.x() >= camera.width || px.y() >= camera.height) {
    return false;
  }
  const Eigen::Vector3d c = camera.Center();
  // Unoccluded when nothing is hit before the point (1e-6 relative slack for rounding).
  return FirstHit(c, p - c) >= 1.0 - 1e-6;
}

MeshingScene MakeRoomScene(int num_cameras, int width, int height) {
  MeshingScene scene;
  ScenePrimitive room;
  room.centre = {0, 0, 1.5};
  room.half_size = {5, 3, 1.5};
  room.hollow = true;
  scene.primitives.push_back(room);
  ScenePrimitive box1;
  box1.centre = {1.5, 0.5, 0.4};
  box1.half_size = {0.6, 0.5, 0.4};
  scene.primitives.push_back(box1);
  ScenePrimitive box2;
  box2.centre = {-2.2, -1.2, 0.3};
  box2.half_size = {0.4, 0.7, 0.3};
  scene.primitives.push_back(box2);
  ScenePrimitive sphere;
  sphere.type = ScenePrimitive::Type::kSphere;
  sphere.centre = {-0.5, 1.4, 0.5};
  sphere.radius = 0.5;
  scene.primitives.push_back(sphere);
  const double kPi = 3.14159265358979323846;
  for (int i = 0; i < num_cameras; ++i) {
    const double a = 2 * kPi * i / num_cameras;
    const Eigen::Vector3d position(3.6 * std::cos(a), 2.0 * std::sin(a),
                                   1.3 + 0.4 * ((i % 3) - 1));
    const double b = a + kPi + 0.5 * std::sin(3 * a);
    const Eigen::Vector3d target(4.5 * std::cos(b), 2.6 * std::sin(b),
                                 0.6 + 0.5 * (i % 2));
    scene.cameras.push_back(LookAtCamera(position, target, width, height, 0.8 * width));
  }
  return scene;
}

MeshingScene MakeObjectScene(int num_cameras, int width, int height) {
  MeshingScene scene;
  ScenePrimitive sphere;
  sphere.type = ScenePrimitive::Type::kSphere;
  sphere.centre = {0, 0, 0};
  sphere.radius = 1;
  scene.primitives.push_back(sphere);
  ScenePrimitive box;
  box.centre = {2.0, 0.3, -0.2};
  box.half_size = {0.5, 0.6, 0.7};
  scene.primitives.push_back(box);
  const double kPi = 3.14159265358979323846;
  for (int i = 0; i < num_cameras; ++i) {
    const double a = 2 * kPi * i / num_cameras;
    const Eigen::Vector3d position(1.0 + 5.5 * std::cos(a), 5.5 * std::sin(a),
                                   (i % 2 ? 2.0 : -1.5));
    scene.cameras.push_back(LookAtCamera(position, Eigen::Vector3d(1.0, 0.15, 0), width,
                                         height, 1.2 * width));
  }
  return scene;
}

SampledCloud SampleScene(const MeshingScene& scene, size_t num_points, double noise,
                         double outlier_fraction, uint64_t seed) {
  SampledCloud cloud;
  const size_t num_cameras = scene.cameras.size();
  // Surface points in parallel chunks, each with its own generator (deterministic).
  const int64_t num_chunks = 64;
  std::vector<SampledCloud> parts(num_chunks);
  ParallelFor(0, num_chunks, [&](int64_t chunk) {
    std::mt19937_64 rng(seed * 1000003 + chunk);
    std::uniform_real_distribution<double> uniform(0, 1);
    std::normal_distribution<double> gauss(0, noise);
    const size_t target =
        num_points * (chunk + 1) / num_chunks - num_points * chunk / num_chunks;
    SampledCloud& part = parts[chunk];
    std::vector<uint32_t> views;
    size_t attempts = 0;
    while (part.true_points.size() < target && attempts++ < 100 * target + 1000) {
      const size_t k = static_cast<size_t>(uniform(rng) * num_cameras) % num_cameras;
      const PinholeCamera& camera = scene.cameras[k];
      const Eigen::Vector3d c = camera.Center();
      const Eigen::Vector3d d = camera.Unproject(uniform(rng) * camera.width,
                                                 uniform(rng) * camera.height, 1.0) -
                                c;
      const double t = scene.FirstHit(c, d);
      if (!std::isfinite(t)) continue;
      const Eigen::Vector3d p = c + t * d;
      views.clear();
      for (size_t j = 0; j < num_cameras; ++j) {
        if (j == k || scene.Sees(j, p)) views.push_back(static_cast<uint32_t>(j));
      }
      if (views.size() < 2) continue;  // fusion keeps points seen at least twice
      part.true_points.push_back(p);
      part.input.points.push_back(p +
                                  Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
      part.input.visibility.push_back(views);
    }
  });
  for (auto& part : parts) {
    cloud.true_points.insert(cloud.true_points.end(), part.true_points.begin(),
                             part.true_points.end());
    cloud.input.points.insert(cloud.input.points.end(), part.input.points.begin(),
                              part.input.points.end());
    cloud.input.visibility.insert(cloud.input.visibility.end(),
                                  part.input.visibility.begin(),
                                  part.input.visibility.end());
  }
  // Outliers: uniform in the bounding box of cameras and surface points, claimed by two
  // cameras whose image they fall in (as a false match would be).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
  for (const auto& p : cloud.true_points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (const auto& cam : scene.cameras) {
    lo = lo.cwiseMin(cam.Center());
    hi = hi.cwiseMax(cam.Center());
  }
  std::mt19937_64 rng(seed ^ 0x9E3779B97F4A7C15ull);
  std::uniform_real_distribution<double> uniform(0, 1);
  const size_t num_outliers =
      static_cast<size_t>(outlier_fraction * cloud.true_points.size());
  size_t attempts = 0;
  while (cloud.num_outliers < num_outliers && attempts++ < 1000 * num_outliers + 1000) {
    const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(
                                       uniform(rng), uniform(rng), uniform(rng)));
    std::vector<uint32_t> views;
    for (int tries = 0; tries < 40 && views.size() < 2; ++tries) {
      const uint32_t k = static_cast<uint32_t>(uniform(rng) * num_cameras) % num_cameras;
      const PinholeCamera& camera = scene.cameras[k];
      const Eigen::Vector3d pc = camera.WorldToCamera(p);
      if (pc.z() <= 0) continue;
      const Eigen::Vector2d px = camera.CameraToPixel(pc);
      if (px.x() < 0 || px.y() < 0 || px.x() >= camera.width || px.y() >= camera.height) {
        continue;
      }
      if (std::find(views.begin(), views.end(), k) == views.end()) views.push_back(k);
    }
    if (views.size() < 2) continue;
    cloud.input.points.push_back(p);
    cloud.input.visibility.push_back(views);
    ++cloud.num_outliers;
  }
  cloud.input.cameras = scene.cameras;
  return cloud;
}

std::vector<double> DistancesToMesh(const TriangleMesh& mesh,
                                    const std::vector<Eigen::Vector3d>& queries,
                                    double max_distance) {
  std::vector<double> out(queries.size(), max_distance);
  if (mesh.faces.empty() || queries.empty()) return out;
  // Triangles binned into a hash grid of cell size h by their bounding boxes grown by h;
  // a query checks its own cell only, which holds every triangle within h of it.
  const double h = max_distance;
  auto key = [h](const Eigen::Vector3d& p) {
    const int64_t x = static_cast<int64_t>(std::floor(p.x() / h));
    const int64_t y = static_cast<int64_t>(std::floor(p.y() / h));
    const int64_t z = static_cast<int64_t>(std::floor(p.z() / h));
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  };
  std::unordered_map<int64_t, std::vector<uint32_t>> grid;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& face = mesh.faces[f];
    Eigen::Vector3d lo = mesh.vertices[face[0]], hi = lo;
    for (int j = 1; j < 3; ++j) {
      lo = lo.cwiseMin(mesh.vertices[face[j]]);
      hi = hi.cwiseMax(mesh.vertices[face[j]]);
    }
    lo.array() -= h;
    hi.array() += h;
    const Eigen::Vector3d cells = ((hi - lo) / h).array().ceil();
    if (cells.prod() > 1e6) continue;  // a giant triangle: skipped (scores as uncovered)
    for (double x = std::floor(lo.x() / h); x <= std::floor(hi.x() / h); ++x) {
      for (double y = std::floor(lo.y() / h); y <= std::floor(hi.y() / h); ++y) {
        for (double z = std::floor(lo.z() / h); z <= std::floor(hi.z() / h); ++z) {
          grid[key(Eigen::Vector3d((x + 0.5) * h, (y + 0.5) * h, (z + 0.5) * h))]
              .push_back(static_cast<uint32_t>(f));
        }
      }
    }
  }
  ParallelFor(0, static_cast<int64_t>(queries.size()), [&](int64_t q) {
    const auto it = grid.find(key(queries[q]));
    if (it == grid.end()) return;
    double best = max_distance;
    for (const uint32_t f : it->second) {
      const auto& face = mesh.faces[f];
      const Eigen::Vector3d closest =
          ClosestOnTriangle(queries[q], mesh.vertices[face[0]], mesh.vertices[face[1]],
                            mesh.vertices[face[2]]);
      best = std::min(best, (closest - queries[q]).norm());
    }
    out[q] = best;
  });
  return out;
}

std::vector<Eigen::Vector3d> SampleMeshFaces(const TriangleMesh& mesh, int per_face,
                                             uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::vector<Eigen::Vector3d> samples;
  samples.reserve(mesh.faces.size() * std::max(per_face, 1));
  for (const auto& face : mesh.faces) {
    const Eigen::Vector3d& a = mesh.vertices[face[0]];
    const Eigen::Vector3d& b = mesh.vertices[face[1]];
    const Eigen::Vector3d& c = mesh.vertices[face[2]];
    samples.push_back((a + b + c) / 3.0);
    for (int s = 1; s < per_face; ++s) {
      double u = uniform(rng), v = uniform(rng);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      samples.push_back(a + u * (b - a) + v * (c - a));
    }
  }
  return samples;
}

MeshAccuracy EvaluateMesh(const MeshingScene& scene, const TriangleMesh& mesh,
                          const std::vector<Eigen::Vector3d>& true_points,
                          double coverage_distance) {
  MeshAccuracy acc;
  std::vector<double> vd(mesh.vertices.size());
  ParallelFor(0, static_cast<int64_t>(vd.size()),
              [&](int64_t i) { vd[i] = scene.DistanceToSurface(mesh.vertices[i]); });
  acc.vertex_mean = Mean(vd);
  acc.vertex_p90 = Percentile90(vd);
  const auto samples = SampleMeshFaces(mesh, 4, 7);
  std::vector<double> fd(samples.size());
  ParallelFor(0, static_cast<int64_t>(fd.size()),
              [&](int64_t i) { fd[i] = scene.DistanceToSurface(samples[i]); });
  acc.face_mean = Mean(fd);
  acc.face_p90 = Percentile90(fd);
  const auto td = DistancesToMesh(mesh, true_points, 2 * coverage_distance);
  size_t covered = 0;
  for (double d : td) covered += d <= coverage_distance;
  acc.coverage =
      true_points.empty() ? 0 : static_cast<double>(covered) / true_points.size();
  return acc;
}

}  // namespace fvs::mvs
