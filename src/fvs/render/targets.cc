#include "fvs/render/targets.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "colmap_ext/camera_models.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/json_number.h"
#include "fvs/util/string_util.h"

namespace fvs {

namespace {

bool ParseDoubles(const std::vector<std::string>& tokens, size_t first, size_t count,
                  double* out) {
  if (tokens.size() < first + count) return false;
  for (size_t i = 0; i < count; ++i) {
    try {
      size_t used = 0;
      out[i] = std::stod(tokens[first + i], &used);
      if (used != tokens[first + i].size()) return false;
    } catch (const std::exception&) {
      return false;
    }
  }
  return true;
}

// A COLMAP id: all of `token` a whole number that fits uint32_t. (Parsed as a double
// and cast, 1e20 or -1 was undefined behaviour: tests/fuzz/target_images_fuzzer.)
bool ParseId(const std::string& token, uint32_t* id) {
  uint32_t value = 0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec != std::errc() || ptr != end) return false;
  *id = value;
  return true;
}

std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream in(line);
  std::string t;
  while (in >> t) tokens.push_back(t);
  return tokens;
}

// cameras.txt: CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] (pinhole models only).
std::map<uint32_t, PinholeCamera> ReadPinholeCamerasTxt(const std::string& path) {
  std::map<uint32_t, PinholeCamera> cameras;
  std::ifstream in(path);
  Require(in.good(), path, "cannot open");
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    line = TrimString(line);
    if (line.empty() || line[0] == '#') continue;
    const std::string where = "line " + std::to_string(line_number);
    const auto tokens = Tokens(line);
    Require(tokens.size() >= 4, path,
            where + ": expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS");
    const int model = colmap::CameraModelIdFromName(tokens[1]);
    Require(model >= 0, path, where + ": unknown camera model " + tokens[1]);
    Require(colmap::CameraModelIsPinhole(model), path,
            where + ": camera model " + tokens[1] +
                " has distortion; targets must be SIMPLE_PINHOLE or PINHOLE");
    const int num_params = colmap::CameraModelNumParams(model);
    double v[3 + 4];
    uint32_t camera_id = 0;
    Require(ParseId(tokens[0], &camera_id) && ParseDoubles(tokens, 2, 2, v + 1) &&
                ParseDoubles(tokens, 4, num_params, v + 3) &&
                static_cast<int>(tokens.size()) == 4 + num_params,
            path, where + ": malformed camera line");
    PinholeCamera c;
    Require(v[1] >= 1 && v[2] >= 1 && v[1] < 1e6 && v[2] < 1e6, path,
            where + ": image size must be positive");
    c.width = static_cast<int>(v[1]);
    c.height = static_cast<int>(v[2]);
    if (model == colmap::kSimplePinhole) {
      c.fx = c.fy = v[3];
      c.cx = v[4];
      c.cy = v[5];
    } else {
      c.fx = v[3];
      c.fy = v[4];
      c.cx = v[5];
      c.cy = v[6];
    }
    Require(c.fx > 0 && c.fy > 0 && std::isfinite(c.fx) && std::isfinite(c.fy) &&
                std::isfinite(c.cx) && std::isfinite(c.cy),
            path, where + ": focal lengths must be positive and finite");
    cameras[camera_id] = c;
  }
  return cameras;
}

bool LooksLikePointsLine(const std::vector<std::string>& tokens) {
  if (tokens.size() % 3 != 0) return false;
  std::vector<double> values(tokens.size());
  return ParseDoubles(tokens, 0, tokens.size(), values.data());
}

Eigen::Matrix3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& center,
                       const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (center - eye).normalized();
  Eigen::Vector3d x = (-up).cross(z);
  if (x.norm() < 1e-9) x = z.unitOrthogonal();  // looking straight up or down
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return R;
}

}  // namespace

void OpenGlCameraToWorldToPose(const Eigen::Matrix4d& c2w, Eigen::Matrix3d* R,
                               Eigen::Vector3d* t) {
  // OpenGL camera axes (x right, y up, z back) -> ours (x right, y down, z forward).
  Eigen::Matrix3d rot = c2w.block<3, 3>(0, 0);
  rot.col(1) *= -1;
  rot.col(2) *= -1;
  // Re-orthonormalise: JSON files carry rounded numbers.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(rot, Eigen::ComputeFullU | Eigen::ComputeFullV);
  rot = svd.matrixU() * svd.matrixV().transpose();
  *R = rot.transpose();
  *t = -(*R) * c2w.block<3, 1>(0, 3);
}

std::vector<TargetCamera> ReadTargetImagesTxt(const std::string& path,
                                              const Scene& scene) {
  const std::string cameras_path =
      (std::filesystem::path(path).parent_path() / "cameras.txt").string();
  std::map<uint32_t, PinholeCamera> cameras;
  if (std::filesystem::exists(cameras_path))
    cameras = ReadPinholeCamerasTxt(cameras_path);
  std::ifstream in(path);
  Require(in.good(), path, "cannot open");
  std::vector<TargetCamera> targets;
  std::string line;
  int line_number = 0;
  bool expect_points = false;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string trimmed = TrimString(line);
    const auto tokens = Tokens(trimmed);
    if (expect_points) {
      expect_points = false;
      // COLMAP writes a (possibly empty) POINTS2D line after each image; tolerate its
      // absence.
      if (trimmed.empty() || LooksLikePointsLine(tokens)) continue;
    }
    if (trimmed.empty() || trimmed[0] == '#') continue;
    const std::string where = "line " + std::to_string(line_number);
    double v[8];
    uint32_t camera_id = 0;
    Require(tokens.size() >= 10 && ParseDoubles(tokens, 0, 8, v) &&
                ParseId(tokens[8], &camera_id),
            path, where + ": expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    for (int i = 1; i < 8; ++i) {
      Require(std::isfinite(v[i]), path, where + ": non-finite pose");
    }
    const Eigen::Vector4d q(v[1], v[2], v[3], v[4]);
    Require(q.norm() > 1e-12, path, where + ": zero quaternion");
    PinholeCamera camera;
    if (cameras.count(camera_id)) {
      camera = cameras[camera_id];
    } else {
      bool found = false;
      for (const SceneView& view : scene.views()) {
        if (view.camera_id == camera_id) {
          camera = view.camera;
          found = true;
          break;
        }
      }
      Require(found, path,
              where + ": camera " + std::to_string(camera_id) +
                  " is neither in a cameras.txt beside this file nor in the workspace");
    }
    camera.R = QuaternionToRotation(q);
    camera.t = Eigen::Vector3d(v[5], v[6], v[7]);
    Require(camera.IsValid(), path, where + ": invalid camera");
    std::string name = tokens[9];
    for (size_t i = 10; i < tokens.size(); ++i) name += " " + tokens[i];
    targets.push_back(
        {std::filesystem::path(name).replace_extension().string(), camera, name});
    expect_points = true;
  }
  Require(!targets.empty(), path, "no target images");
  return targets;
}

std::vector<TargetCamera> ReadNerfstudioCameraPath(const std::string& path) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(ReadFileToString(path));
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not valid JSON: ") + e.what());
  }
  std::vector<TargetCamera> targets;
  try {
    int width = 0, height = 0;
    Require(JsonToInt(json.at("render_width"), 1, 99999, &width) &&
                JsonToInt(json.at("render_height"), 1, 99999, &height),
            path, "render_width and render_height must be positive whole numbers");
    const auto& frames = json.at("camera_path");
    Require(frames.is_array() && !frames.empty(), path, "camera_path is empty");
    for (size_t i = 0; i < frames.size(); ++i) {
      const std::string where = "camera_path[" + std::to_string(i) + "]";
      std::vector<double> m;
      for (const auto& value : frames[i].at("camera_to_world")) {
        if (value.is_array()) {
          for (const auto& x : value) m.push_back(x.get<double>());
        } else {
          m.push_back(value.get<double>());
        }
      }
      Require(m.size() == 16 || m.size() == 12, path,
              where + ": camera_to_world needs 16 (or 12) numbers");
      Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
      for (size_t k = 0; k < m.size(); ++k) c2w(k / 4, k % 4) = m[k];
      Require(c2w.allFinite(), path, where + ": non-finite camera_to_world");
      const double fov = frames[i].at("fov").get<double>();
      Require(fov > 0 && fov < 180, path, where + ": fov must be in (0, 180) degrees");
      PinholeCamera c;
      c.width = width;
      c.height = height;
      c.fy = 0.5 * height / std::tan(0.5 * fov * M_PI / 180.0);
      c.fx = c.fy;  // square pixels; "aspect" is render_width / render_height
      c.cx = 0.5 * width;
      c.cy = 0.5 * height;
      Require(std::abs(c2w.block<3, 3>(0, 0).determinant() - 1.0) < 1e-3, path,
              where + ": camera_to_world is not a rotation");
      OpenGlCameraToWorldToPose(c2w, &c.R, &c.t);
      Require(c.IsValid(), path, where + ": invalid camera");
      targets.push_back({FrameName(static_cast<int>(i)), c, ""});
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not a nerfstudio camera path: ") + e.what());
  }
  return targets;
}

std::vector<TargetCamera> OrbitTargets(const Scene& scene, int num_views) {
  Require(num_views >= 1, "--orbit", "needs at least 1 view");
  const int n = scene.num_views();
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const SceneView& v : scene.views()) {
    up -= v.camera.R.row(1).transpose();  // camera y points down
    const Eigen::Vector3d d = v.camera.ViewDirection();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * v.camera.Center();
  }
  up = up.norm() > 1e-9 ? up.normalized() : Eigen::Vector3d(0, -1, 0);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  Eigen::Vector3d center;
  if (eig.eigenvalues()(0) > 1e-2 * n) {
    center = A.ldlt().solve(b);
  } else {  // near-parallel optical axes: the mesh centroid
    center = Eigen::Vector3d::Zero();
    for (const auto& x : scene.mesh().vertices) center += x;
    center /= std::max<size_t>(1, scene.mesh().vertices.size());
  }
  double height = 0, radius = 0;
  for (const SceneView& v : scene.views()) {
    const Eigen::Vector3d rel = v.camera.Center() - center;
    height += rel.dot(up) / n;
    radius += (rel - rel.dot(up) * up).norm() / n;
  }
  Eigen::Vector3d e1 = scene.view(0).camera.Center() - center;
  e1 -= e1.dot(up) * up;
  e1 = e1.norm() > 1e-9 ? e1.normalized() : up.unitOrthogonal();
  const Eigen::Vector3d e2 = up.cross(e1);
  if (radius < 1e-9) radius = 1.0;
  std::vector<TargetCamera> targets;
  for (int i = 0; i < num_views; ++i) {
    const double a = 2.0 * M_PI * i / num_views;
    const Eigen::Vector3d eye =
        center + height * up + radius * (std::cos(a) * e1 + std::sin(a) * e2);
    PinholeCamera c = scene.view(0).camera;
    c.R = LookAt(eye, center, up);
    c.t = -c.R * eye;
    targets.push_back({FrameName(i), scene.ToWorldCamera(c), ""});
  }
  return targets;
}

std::vector<TargetCamera> InterpolateTargets(const Scene& scene, int num_per_segment) {
  Require(num_per_segment >= 1, "--interpolate", "needs at least 1 view per segment");
  std::vector<const SceneView*> views;
  for (const SceneView& v : scene.views()) views.push_back(&v);
  std::sort(views.begin(), views.end(),
            [](const SceneView* a, const SceneView* b) { return a->name < b->name; });
  std::vector<TargetCamera> targets;
  for (size_t k = 0; k + 1 < views.size(); ++k) {
    const PinholeCamera& a = views[k]->camera;
    const PinholeCamera& b = views[k + 1]->camera;
    const Eigen::Quaterniond qa(a.R), qb(b.R);
    for (int j = 0; j < num_per_segment; ++j) {
      const double s = static_cast<double>(j) / num_per_segment;
      PinholeCamera c = a;
      if (a.width == b.width && a.height == b.height) {
        c.fx = (1 - s) * a.fx + s * b.fx;
        c.fy = (1 - s) * a.fy + s * b.fy;
        c.cx = (1 - s) * a.cx + s * b.cx;
        c.cy = (1 - s) * a.cy + s * b.cy;
      }
      c.R = qa.slerp(s, qb).normalized().toRotationMatrix();
      const Eigen::Vector3d eye = (1 - s) * a.Center() + s * b.Center();
      c.t = -c.R * eye;
      targets.push_back(
          {FrameName(static_cast<int>(targets.size())), scene.ToWorldCamera(c), ""});
    }
  }
  targets.push_back({FrameName(static_cast<int>(targets.size())),
                     scene.ToWorldCamera(views.back()->camera), ""});
  return targets;
}

PinholeCamera ResizeTarget(const PinholeCamera& camera, int width, int height,
                           double scale) {
  Require(std::isfinite(scale) && scale > 0, "--scale", "must be positive");
  Require(width >= 0 && height >= 0, "--width/--height", "must not be negative");
  int w = camera.width, h = camera.height;
  if (width > 0 && height > 0) {
    w = width;
    h = height;
  } else if (width > 0) {
    w = width;
    h = static_cast<int>(
        std::lround(static_cast<double>(width) * camera.height / camera.width));
  } else if (height > 0) {
    h = height;
    w = static_cast<int>(
        std::lround(static_cast<double>(height) * camera.width / camera.height));
  }
  const double sw = std::round(w * scale), sh = std::round(h * scale);
  Require(sw >= 1 && sh >= 1 && sw <= 65536 && sh <= 65536, "--width/--height/--scale",
          "gives an output size of " + std::to_string(sw) + "x" + std::to_string(sh));
  if (static_cast<int>(sw) == camera.width && static_cast<int>(sh) == camera.height) {
    return camera;
  }
  return camera.Resized(static_cast<int>(sw), static_cast<int>(sh));
}

std::string FrameName(int index) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "frame_%05d", index);
  return buffer;
}

}  // namespace fvs
