#include "fvs/synthetic/synthetic_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "fvs/synthetic/camera_path.h"
#include "fvs/synthetic/primitives.h"
#include "fvs/synthetic/random.h"
#include "fvs/util/error.h"

namespace fvs {

void SyntheticSceneOptions::Check() const {
  const std::string subject = "SyntheticScene";
  Require(num_views >= 1 && num_views <= 100000, subject,
          "num_views must be in [1, 100000], got " + std::to_string(num_views));
  Require(width >= 16 && width <= 16384 && height >= 16 && height <= 16384, subject,
          "width and height must be in [16, 16384], got " + std::to_string(width) + "x" +
              std::to_string(height));
  Require(supersampling >= 1 && supersampling <= 8, subject,
          "supersampling must be in [1, 8], got " + std::to_string(supersampling));
  Require(std::isfinite(focal_factor) && focal_factor >= 0.2 && focal_factor <= 5,
          subject, "focal_factor must be in [0.2, 5]");
  Require(std::isfinite(path_step_degrees) && path_step_degrees > 0 &&
              path_step_degrees <= 90,
          subject, "path_step_degrees must be in (0, 90]");
  Require(num_sparse_points >= 0 && num_sparse_points <= 10000000, subject,
          "num_sparse_points must be in [0, 10000000]");
}

namespace {

using synthetic::LabeledMesh;
using synthetic::SceneRandom;

constexpr double kPi = 3.14159265358979323846;

struct Footprint {
  Eigen::Vector2d center;
  double radius;
};

// Room faces are split more coarsely than objects: they are large and flat.
constexpr double kRoomMaxEdge = 0.25;
constexpr double kObjectMaxEdge = 0.15;
// Closest an object may come to a camera centre (horizontally, beyond its footprint).
constexpr double kCameraClearance = 0.8;

class SceneBuilder {
 public:
  SceneBuilder(SyntheticScene* scene, SceneRandom* random)
      : scene_(scene), random_(random) {}

  int NewMaterial(double scale) {
    scene_->materials.push_back(synthetic::RandomMaterial(random_, scale));
    return static_cast<int>(scene_->materials.size()) - 1;
  }
  // One colour all over (drawn as usual first, so the rest of the scene stays the same):
  // a textureless wall, floor or ceiling, where NCC says nothing.
  static void MakePlain(synthetic::ProceduralMaterial* m) {
    m->palette[1] = m->palette[0];
    m->pattern_strength = 0;
    m->grain_strength = 0;
  }
  int NewPrimitive(const std::string& name) {
    scene_->primitive_names.push_back(name);
    return static_cast<int>(scene_->primitive_names.size()) - 1;
  }

  void AddRoom(const Eigen::Vector3d& half) {
    // One material per room face, so the walls are told apart.
    const char* names[6] = {"room.wall_x-", "room.wall_x+", "room.wall_y-",
                            "room.wall_y+", "room.floor",   "room.ceiling"};
    const Eigen::Vector3d center(0, 0, half.z());
    for (int axis = 0; axis < 3; ++axis) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      for (int sign = -1; sign <= 1; sign += 2) {
        const int primitive = NewPrimitive(names[2 * axis + (sign > 0)]);
        const int material = NewMaterial(random_->Uniform(1.2, 1.8));
        if (scene_->options.plain_walls) MakePlain(&scene_->materials[material]);
        Eigen::Vector3d corner = Eigen::Vector3d::Zero(), u = corner, v = corner;
        corner[axis] = sign * half[axis];
        corner[a1] = -half[a1];
        corner[a2] = -half[a2];
        u[a1] = 2 * half[a1];
        v[a2] = 2 * half[a2];
        // e_a1 x e_a2 = +e_axis; the visible side of the face at +half is towards -axis.
        if (sign > 0) std::swap(u, v);
        synthetic::AddQuad(center + corner, u, v, kRoomMaxEdge, primitive, material,
                           &mesh_);
      }
    }
  }

  bool Fits(const Footprint& f, const Eigen::Vector2d& room_half) const {
    if (std::abs(f.center.x()) + f.radius > room_half.x() - 0.05 ||
        std::abs(f.center.y()) + f.radius > room_half.y() - 0.05) {
      return false;
    }
    for (const Footprint& other : footprints_) {
      if ((other.center - f.center).norm() < other.radius + f.radius + 0.15) return false;
    }
    for (const PinholeCamera& camera : scene_->cameras) {
      const Eigen::Vector2d c = camera.Center().head<2>();
      if ((c - f.center).norm() < f.radius + kCameraClearance) return false;
    }
    return true;
  }

  // Tries random positions from `sample` until one fits; false when none does.
  template <typename Sampler>
  bool Place(double radius, const Eigen::Vector2d& room_half, Sampler sample,
             Eigen::Vector2d* center) {
    for (int attempt = 0; attempt < 300; ++attempt) {
      const Footprint f{sample(), radius};
      if (Fits(f, room_half)) {
        footprints_.push_back(f);
        *center = f.center;
        return true;
      }
    }
    return false;
  }

  Eigen::Vector3d Draw(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
    double v[3];
    random_->Uniform3(lo.data(), hi.data(), v);
    return {v[0], v[1], v[2]};
  }

  Eigen::Matrix3d RandomYaw() {
    return Eigen::AngleAxisd(random_->Uniform(0, 2 * kPi), Eigen::Vector3d::UnitZ())
        .toRotationMatrix();
  }

  void AddCentralObject(int kind, const Eigen::Vector2d& room_half,
                        const synthetic::PathLayout& path) {
    auto sample = [&] {
      // Inside half the path ellipse: seen by every camera, in front of the far walls.
      const double r = 0.5 * std::sqrt(random_->Uniform());
      const double a = random_->Uniform(0, 2 * kPi);
      return Eigen::Vector2d(path.radius_x * r * std::cos(a),
                             path.radius_y * r * std::sin(a));
    };
    Eigen::Vector2d c;
    switch (kind) {
      case 0: {  // box, sometimes with a ball on top
        const Eigen::Vector3d half = Draw({0.15, 0.15, 0.15}, {0.45, 0.45, 0.5});
        if (!Place(half.head<2>().norm(), room_half, sample, &c)) return;
        const Eigen::Matrix3d yaw = RandomYaw();
        const int material = NewMaterial(random_->Uniform(0.6, 1.0));
        synthetic::AddBox(Eigen::Vector3d(c.x(), c.y(), half.z()), half, yaw, false,
                          kObjectMaxEdge, NewPrimitive("box"), material, &mesh_);
        if (random_->Uniform() < 0.4) {
          const double r = std::min(half.x(), half.y()) * random_->Uniform(0.5, 0.9);
          synthetic::AddSphere(Eigen::Vector3d(c.x(), c.y(), 2 * half.z() + r), r, 32, 16,
                               NewPrimitive("sphere"),
                               NewMaterial(random_->Uniform(0.5, 0.8)), &mesh_);
        }
        break;
      }
      case 1: {  // ball on the floor
        const double r = random_->Uniform(0.2, 0.45);
        if (!Place(r, room_half, sample, &c)) return;
        synthetic::AddSphere(Eigen::Vector3d(c.x(), c.y(), r), r, 32, 16,
                             NewPrimitive("sphere"),
                             NewMaterial(random_->Uniform(0.5, 0.9)), &mesh_);
        break;
      }
      case 2: {  // cylinder
        const double r = random_->Uniform(0.12, 0.35);
        const double h = random_->Uniform(0.4, 1.3);
        if (!Place(r, room_half, sample, &c)) return;
        synthetic::AddCylinder(Eigen::Vector3d(c.x(), c.y(), 0), r, h, 32, kObjectMaxEdge,
                               NewPrimitive("cylinder"),
                               NewMaterial(random_->Uniform(0.5, 0.9)), &mesh_);
        break;
      }
      default: {  // staircase: sharp corners at several depths
        const int steps = random_->UniformInt(3, 5);
        const double depth = random_->Uniform(0.22, 0.32);
        const double rise = random_->Uniform(0.12, 0.22);
        const double width = random_->Uniform(0.5, 0.9);
        const Eigen::Vector2d half_size(0.5 * steps * depth, 0.5 * width);
        if (!Place(half_size.norm(), room_half, sample, &c)) return;
        const Eigen::Matrix3d yaw = RandomYaw();
        const int primitive = NewPrimitive("staircase");
        const int material = NewMaterial(random_->Uniform(0.6, 1.0));
        for (int s = 0; s < steps; ++s) {
          const Eigen::Vector3d half(0.5 * depth, 0.5 * width, 0.5 * rise * (s + 1));
          const Eigen::Vector3d local(-half_size.x() + depth * (s + 0.5), 0, 0);
          synthetic::AddBox(Eigen::Vector3d(c.x(), c.y(), half.z()) + yaw * local, half,
                            yaw, false, kObjectMaxEdge, primitive, material, &mesh_);
        }
        break;
      }
    }
  }

  void AddWallObject(int kind, const Eigen::Vector2d& room_half,
                     const synthetic::PathLayout& path) {
    auto sample = [&] {
      // Between the camera path and the walls: background for the far side of the path.
      for (;;) {
        const double px = random_->Symmetric(room_half.x());
        const double py = random_->Symmetric(room_half.y());
        const Eigen::Vector2d p(px, py);
        const double e = std::hypot(p.x() / path.radius_x, p.y() / path.radius_y);
        if (e > 1.2) return p;
      }
    };
    Eigen::Vector2d c;
    if (kind == 0) {  // cabinet
      const Eigen::Vector3d half = Draw({0.2, 0.2, 0.5}, {0.5, 0.4, 1.0});
      if (!Place(half.head<2>().norm(), room_half, sample, &c)) return;
      const Eigen::Matrix3d yaw = RandomYaw();
      const int material = NewMaterial(random_->Uniform(0.7, 1.2));
      synthetic::AddBox(Eigen::Vector3d(c.x(), c.y(), half.z()), half, yaw, false,
                        kObjectMaxEdge, NewPrimitive("cabinet"), material, &mesh_);
    } else {  // pillar
      const double r = random_->Uniform(0.15, 0.3);
      const double h = random_->Uniform(1.5, 2.6);
      if (!Place(r, room_half, sample, &c)) return;
      synthetic::AddCylinder(Eigen::Vector3d(c.x(), c.y(), 0), r, h, 32, kObjectMaxEdge,
                             NewPrimitive("pillar"),
                             NewMaterial(random_->Uniform(0.7, 1.2)), &mesh_);
    }
  }

  LabeledMesh& mesh() { return mesh_; }

 private:
  SyntheticScene* scene_;
  SceneRandom* random_;
  LabeledMesh mesh_;
  std::vector<Footprint> footprints_;
};

uint8_t ToByte(double linear) {
  const double srgb = std::pow(std::clamp(linear, 0.0, 1.0), 1.0 / 2.2);
  return static_cast<uint8_t>(std::lround(255.0 * srgb));
}

}  // namespace

SyntheticScene BuildSyntheticScene(const SyntheticSceneOptions& options) {
  options.Check();
  SyntheticScene scene;
  scene.options = options;
  SceneRandom random(synthetic::Mix64(options.seed ^ 0x5EED5CE4Eull));

  const double room_lo[3] = {4.5, 3.5, 1.4}, room_hi[3] = {5.5, 4.5, 1.7};
  double room_draw[3];
  random.Uniform3(room_lo, room_hi, room_draw);
  const Eigen::Vector3d room_half(room_draw[0], room_draw[1], room_draw[2]);
  synthetic::PathLayout path;
  path.radius_x = 0.62 * room_half.x();
  path.radius_y = 0.62 * room_half.y();
  path.eye_height = random.Uniform(1.45, 1.65);
  const double target_lo[3] = {-0.2, -0.2, 0.5}, target_hi[3] = {0.2, 0.2, 0.7};
  double target[3];
  random.Uniform3(target_lo, target_hi, target);
  path.target = Eigen::Vector3d(target[0], target[1], target[2]);
  scene.cameras = synthetic::MakeHandheldPath(options, path, &random);
  for (int i = 0; i < options.num_views; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", i);
    scene.image_names.push_back(name);
  }

  SceneBuilder builder(&scene, &random);
  builder.AddRoom(room_half);
  const Eigen::Vector2d floor_half = room_half.head<2>();
  // Central objects: one staircase at most, the rest drawn from box / ball / cylinder.
  const int num_central = random.UniformInt(5, 7);
  builder.AddCentralObject(3, floor_half, path);
  for (int i = 1; i < num_central; ++i) {
    builder.AddCentralObject(random.UniformInt(0, 2), floor_half, path);
  }
  const int num_wall = random.UniformInt(4, 6);
  for (int i = 0; i < num_wall; ++i) {
    builder.AddWallObject(random.UniformInt(0, 1), floor_half, path);
  }

  synthetic::LabeledMesh& labeled = builder.mesh();
  scene.mesh = std::move(labeled.mesh);
  scene.face_primitive = std::move(labeled.face_primitive);
  scene.face_material = std::move(labeled.face_material);

  // Vertex colours: the albedo of the vertex's own material (vertices are not shared
  // between primitives, see primitives.h).
  std::vector<int> vertex_material(scene.mesh.vertices.size(), 0);
  for (size_t f = 0; f < scene.mesh.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k)
      vertex_material[scene.mesh.faces[f][k]] = scene.face_material[f];
  }
  scene.mesh.colors.resize(scene.mesh.vertices.size());
  for (size_t v = 0; v < scene.mesh.vertices.size(); ++v) {
    const Eigen::Vector3d a =
        scene.materials[vertex_material[v]].Albedo(scene.mesh.vertices[v]);
    scene.mesh.colors[v] = Vector3ub(ToByte(a.x()), ToByte(a.y()), ToByte(a.z()));
  }

  scene.bounds.setEmpty();
  for (const Eigen::Vector3d& v : scene.mesh.vertices) scene.bounds.extend(v);
  scene.scene_size = scene.bounds.diagonal().norm();

  const double light_yaw = random.Uniform(0, 2 * kPi);
  scene.key_light =
      Eigen::Vector3d(0.45 * std::cos(light_yaw), 0.45 * std::sin(light_yaw), 1.0)
          .normalized();
  scene.fill_light = Eigen::Vector3d(-0.8 * std::cos(light_yaw + 0.7),
                                     -0.8 * std::sin(light_yaw + 0.7), 0.35)
                         .normalized();

  scene.bvh = synthetic::MeshBvh(scene.mesh);
  return scene;
}

}  // namespace fvs
