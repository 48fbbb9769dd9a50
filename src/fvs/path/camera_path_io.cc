// camera_path.json (nerfstudio) and COLMAP images.txt writers, keyframe reader.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "fvs/path/camera_path.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/json_number.h"

namespace fvs {

namespace {

// Our world-to-camera pose -> camera-to-world in OpenGL axes (x right, y up, z back),
// row-major 16 numbers.
std::vector<double> CameraToWorldOpenGl(const PinholeCamera& c) {
  Eigen::Matrix3d rot = c.R.transpose();
  rot.col(1) *= -1;
  rot.col(2) *= -1;
  const Eigen::Vector3d centre = c.Center();
  std::vector<double> m(16, 0.0);
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) m[4 * r + k] = rot(r, k);
    m[4 * r + 3] = centre(r);
  }
  m[15] = 1;
  return m;
}

double VerticalFovDeg(const PinholeCamera& c) {
  return 2 * std::atan(0.5 * c.height / c.fy) * 180 / M_PI;
}

std::vector<double> ReadNumbers(const nlohmann::json& value) {
  std::vector<double> m;
  if (value.is_string())
    return ReadNumbers(nlohmann::json::parse(value.get<std::string>()));
  for (const auto& v : value) {
    if (v.is_array()) {
      for (const auto& x : v) m.push_back(x.get<double>());
    } else {
      m.push_back(v.get<double>());
    }
  }
  return m;
}

}  // namespace

void WriteNerfstudioCameraPath(const std::string& path,
                               const std::vector<CameraPathKeyframe>& keys,
                               const std::vector<TargetCamera>& frames,
                               const CameraPathOptions& options) {
  Require(!frames.empty(), path, "no frames to write");
  const int w = frames.front().camera.width, h = frames.front().camera.height;
  nlohmann::json json;
  json["camera_type"] = "perspective";
  json["render_width"] = w;
  json["render_height"] = h;
  json["fps"] = options.fps;
  json["seconds"] = frames.size() > 1 ? (frames.size() - 1) / options.fps : 0.0;
  json["smoothness_value"] = options.smooth ? options.jerk_weight : 0.0;
  json["is_cycle"] = false;
  json["crop"] = nullptr;
  nlohmann::json keyframes = nlohmann::json::array();
  for (const CameraPathKeyframe& k : keys) {
    Require(k.camera.IsValid(), path, "keyframe " + k.name + " is not a valid camera");
    nlohmann::json entry;
    entry["name"] = k.name;
    // "matrix" as the viser viewer writes it (row-major camera-to-world, OpenGL axes);
    // camera_to_world is the same, named as in camera_path.
    entry["matrix"] = CameraToWorldOpenGl(k.camera);
    entry["camera_to_world"] = CameraToWorldOpenGl(k.camera);
    entry["fov"] = VerticalFovDeg(k.camera);
    entry["aspect"] = static_cast<double>(k.camera.width) / k.camera.height;
    entry["width"] = k.camera.width;
    entry["height"] = k.camera.height;
    keyframes.push_back(entry);
  }
  json["keyframes"] = keyframes;
  nlohmann::json camera_path = nlohmann::json::array();
  for (const TargetCamera& f : frames) {
    const PinholeCamera& c = f.camera;
    Require(c.IsValid(), path, f.name + " is not a valid camera");
    Require(
        c.width == w && c.height == h, path,
        "every frame of a nerfstudio path has the same size (" + f.name + " differs)");
    Require(std::abs(c.fx - c.fy) <= 1e-9 * c.fy &&
                std::abs(c.cx - 0.5 * w) <= 1e-9 * w &&
                std::abs(c.cy - 0.5 * h) <= 1e-9 * h,
            path,
            f.name +
                ": a nerfstudio path holds square pixels and a centred principal point "
                "only");
    nlohmann::json entry;
    entry["camera_to_world"] = CameraToWorldOpenGl(c);
    entry["fov"] = VerticalFovDeg(c);
    entry["aspect"] = static_cast<double>(w) / h;
    camera_path.push_back(entry);
  }
  json["camera_path"] = camera_path;
  WriteFileAtomic(path, [&](std::ostream& out) { out << json.dump(2) << "\n"; });
}

std::vector<CameraPathKeyframe> ReadNerfstudioKeyframes(const std::string& path) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(ReadFileToString(path));
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not valid JSON: ") + e.what());
  }
  if (!json.contains("keyframes") || !json["keyframes"].is_array() ||
      json["keyframes"].empty()) {
    std::vector<CameraPathKeyframe> keys;
    for (TargetCamera& t : ReadNerfstudioCameraPath(path))
      keys.push_back({t.name, t.camera});
    return keys;
  }
  std::vector<CameraPathKeyframe> keys;
  try {
    // An optional size: `fallback` when absent; present, it must be a size.
    auto size_of = [&](const nlohmann::json& object, const char* key, int fallback,
                       const std::string& where) {
      int size = fallback;
      if (!object.contains(key)) return size;
      Require(JsonToInt(object[key], 0, 99999, &size), path,
              where + key + " must be a whole number in 0..99999");
      return size;
    };
    const int render_w = size_of(json, "render_width", 0, "");
    const int render_h = size_of(json, "render_height", 0, "");
    const auto& list = json["keyframes"];
    for (size_t i = 0; i < list.size(); ++i) {
      const auto& k = list[i];
      const std::string where = "keyframes[" + std::to_string(i) + "]";
      Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
      std::vector<double> m;
      bool column_major = false;
      if (k.contains("camera_to_world")) {
        m = ReadNumbers(k["camera_to_world"]);
      } else {
        Require(k.contains("matrix"), path, where + ": needs camera_to_world or matrix");
        column_major = k["matrix"].is_string();  // three.js elements (legacy viewer)
        m = ReadNumbers(k["matrix"]);
      }
      Require(m.size() == 16 || m.size() == 12, path,
              where + ": the camera matrix needs 16 (or 12) numbers");
      for (size_t e = 0; e < m.size(); ++e) {
        if (column_major) {
          c2w(e % 4, e / 4) = m[e];
        } else {
          c2w(e / 4, e % 4) = m[e];
        }
      }
      Require(c2w.allFinite(), path, where + ": non-finite camera matrix");
      Require(std::abs(c2w.block<3, 3>(0, 0).determinant() - 1.0) < 1e-3, path,
              where + ": the camera matrix is not a rotation");
      const double fov = k.at("fov").get<double>();
      Require(std::isfinite(fov) && fov > 0 && fov < 180, path,
              where + ": fov must be in (0, 180) degrees");
      const int height = size_of(k, "height", render_h, where + ": ");
      double aspect = k.value("aspect", render_h > 0 ? 1.0 * render_w / render_h : 0.0);
      int width = size_of(k, "width", 0, where + ": ");
      if (width <= 0 && render_w > 0) width = render_w;
      // Checked before the cast: a huge or non-finite aspect has no int width.
      if (width <= 0 && aspect > 0 && aspect * height < 100000) {
        width = static_cast<int>(std::lround(aspect * height));
      }
      Require(width > 0 && height > 0 && width < 100000 && height < 100000, path,
              where + ": no usable size (render_width/height or width/height)");
      CameraPathKeyframe key;
      key.name = k.value("name", "keyframe_" + std::to_string(i));
      PinholeCamera& c = key.camera;
      c.width = width;
      c.height = height;
      c.fy = 0.5 * height / std::tan(0.5 * fov * M_PI / 180);
      c.fx = c.fy;
      c.cx = 0.5 * width;
      c.cy = 0.5 * height;
      OpenGlCameraToWorldToPose(c2w, &c.R, &c.t);
      Require(c.IsValid(), path, where + ": invalid camera");
      keys.push_back(key);
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not a nerfstudio camera path: ") + e.what());
  }
  return keys;
}

void WriteTargetImagesTxt(const std::string& path,
                          const std::vector<TargetCamera>& frames) {
  Require(!frames.empty(), path, "no frames to write");
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!folder.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    Require(!ec, folder.string(), "cannot create the folder: " + ec.message());
  }
  // One PINHOLE camera per distinct intrinsics.
  using Key = std::tuple<int, int, double, double, double, double>;
  std::map<Key, int> camera_ids;
  std::vector<int> frame_camera;
  std::ostringstream cameras;
  cameras.precision(17);
  cameras << "# Camera list with one line of data per camera:\n"
          << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  for (const TargetCamera& f : frames) {
    const PinholeCamera& c = f.camera;
    Require(c.IsValid(), path, f.name + " is not a valid camera");
    const Key key{c.width, c.height, c.fx, c.fy, c.cx, c.cy};
    auto it = camera_ids.find(key);
    if (it == camera_ids.end()) {
      const int id = static_cast<int>(camera_ids.size()) + 1;
      it = camera_ids.emplace(key, id).first;
      cameras << id << " PINHOLE " << c.width << " " << c.height << " " << c.fx << " "
              << c.fy << " " << c.cx << " " << c.cy << "\n";
    }
    frame_camera.push_back(it->second);
  }
  std::ostringstream images;
  images.precision(17);
  images << "# Image list with two lines of data per image:\n"
         << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
         << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
         << "# Number of images: " << frames.size()
         << ", mean observations per image: 0\n";
  for (size_t i = 0; i < frames.size(); ++i) {
    const PinholeCamera& c = frames[i].camera;
    const Eigen::Vector4d q = RotationToQuaternion(c.R);
    std::string name =
        frames[i].image_name.empty() ? frames[i].name + ".png" : frames[i].image_name;
    images << i + 1 << " " << q(0) << " " << q(1) << " " << q(2) << " " << q(3) << " "
           << c.t(0) << " " << c.t(1) << " " << c.t(2) << " " << frame_camera[i] << " "
           << name << "\n\n";
  }
  const std::string cameras_path = (folder / "cameras.txt").string();
  const std::string points_path = (folder / "points3D.txt").string();
  WriteFileAtomic(cameras_path, [&](std::ostream& out) { out << cameras.str(); });
  WriteFileAtomic(points_path, [&](std::ostream& out) {
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << "# Number of points: 0, mean track length: 0\n";
  });
  WriteFileAtomic(path, [&](std::ostream& out) { out << images.str(); });
}

}  // namespace fvs
