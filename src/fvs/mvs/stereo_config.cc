#include "fvs/mvs/stereo_config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "colmap_ext/workspace.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs::mvs {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kDefaultAutoSources = 20;

double Percentile(std::vector<double> values, double percent) {
  const size_t index =
      std::min(values.size() - 1, static_cast<size_t>(percent / 100.0 * values.size()));
  std::nth_element(values.begin(), values.begin() + index, values.end());
  return values[index];
}

}  // namespace

std::vector<uint32_t> SelectSourceImages(const colmap::Reconstruction& reconstruction,
                                         uint32_t image_id, int max_num_sources,
                                         double min_triangulation_angle) {
  const auto ref_it = reconstruction.images.find(image_id);
  if (ref_it == reconstruction.images.end() || max_num_sources <= 0) return {};
  const colmap::Image& ref = ref_it->second;
  const Eigen::Vector3d ref_center = ref.ProjectionCenter();
  std::map<uint32_t, Eigen::Vector3d> centers;
  for (const auto& [id, image] : reconstruction.images)
    centers[id] = image.ProjectionCenter();
  const double min_angle = min_triangulation_angle * kPi / 180.0;
  std::map<uint32_t, int> shared;
  for (const colmap::Point2D& p : ref.points2D) {
    if (p.point3D_id == colmap::kInvalidPoint3DId) continue;
    const auto point_it = reconstruction.points3D.find(p.point3D_id);
    if (point_it == reconstruction.points3D.end()) continue;
    const Eigen::Vector3d& xyz = point_it->second.xyz;
    const Eigen::Vector3d ray_ref = (xyz - ref_center).normalized();
    std::vector<uint32_t> counted;  // a track may list an image twice
    for (const colmap::TrackElement& el : point_it->second.track) {
      if (el.image_id == image_id || !centers.count(el.image_id)) continue;
      if (std::find(counted.begin(), counted.end(), el.image_id) != counted.end())
        continue;
      counted.push_back(el.image_id);
      const Eigen::Vector3d ray = (xyz - centers[el.image_id]).normalized();
      const double angle = std::acos(std::clamp(ray_ref.dot(ray), -1.0, 1.0));
      if (angle >= min_angle) ++shared[el.image_id];
    }
  }
  std::vector<std::pair<int, uint32_t>> ranked;
  for (const auto& [id, count] : shared) ranked.push_back({-count, id});
  std::sort(ranked.begin(), ranked.end());
  std::vector<uint32_t> result;
  for (const auto& [neg_count, id] : ranked) {
    if (static_cast<int>(result.size()) >= max_num_sources) break;
    result.push_back(id);
  }
  return result;
}

bool ComputeDepthRange(const colmap::Reconstruction& reconstruction, uint32_t image_id,
                       double* depth_min, double* depth_max) {
  const auto it = reconstruction.images.find(image_id);
  if (it == reconstruction.images.end()) return false;
  const colmap::Image& image = it->second;
  const Eigen::Matrix3d R = image.Rotation();
  std::vector<double> depths;
  for (const colmap::Point2D& p : image.points2D) {
    if (p.point3D_id == colmap::kInvalidPoint3DId) continue;
    const auto point_it = reconstruction.points3D.find(p.point3D_id);
    if (point_it == reconstruction.points3D.end()) continue;
    const double z = (R * point_it->second.xyz + image.tvec).z();
    if (z > 0 && std::isfinite(z)) depths.push_back(z);
  }
  if (depths.size() < 3) {
    // Few observations: every point in front of the camera that lands in the image.
    depths.clear();
    const PinholeCamera camera = reconstruction.PinholeFor(image_id);
    for (const auto& [id, point] : reconstruction.points3D) {
      const Eigen::Vector3d xc = camera.WorldToCamera(point.xyz);
      if (!(xc.z() > 0)) continue;
      const Eigen::Vector2d uv = camera.CameraToPixel(xc);
      if (uv.x() >= 0 && uv.y() >= 0 && uv.x() <= camera.width &&
          uv.y() <= camera.height) {
        depths.push_back(xc.z());
      }
    }
  }
  if (depths.empty()) return false;
  *depth_min = 0.75 * Percentile(depths, 1);
  *depth_max = 1.25 * Percentile(depths, 99);
  if (!(*depth_max > *depth_min)) *depth_max = 2.0 * *depth_min;
  return std::isfinite(*depth_min) && std::isfinite(*depth_max) && *depth_min > 0;
}

std::vector<StereoProblem> ReadPatchMatchConfig(
    const std::string& path, const colmap::Reconstruction& reconstruction,
    double min_triangulation_angle) {
  std::vector<std::string> lines;
  {
    std::istringstream in(ReadFileToString(path));
    std::string line;
    while (std::getline(in, line)) {
      line = TrimString(line);
      if (!line.empty() && line[0] != '#') lines.push_back(line);
    }
  }
  Require(lines.size() % 2 == 0, path,
          "expected pairs of lines (an image name, then its sources), got an odd count");
  auto image_id = [&](const std::string& name) {
    const colmap::Image* image = reconstruction.FindImageByName(name);
    Require(image != nullptr, path, "image '" + name + "' is not in the sparse model");
    return image->image_id;
  };
  std::vector<StereoProblem> problems;
  for (size_t i = 0; i < lines.size(); i += 2) {
    StereoProblem problem;
    problem.ref_image_id = image_id(lines[i]);
    const std::vector<std::string> fields = SplitString(lines[i + 1], ",");
    std::vector<std::string> names;
    for (const std::string& f : fields) {
      const std::string name = TrimString(f);
      if (!name.empty()) names.push_back(name);
    }
    Require(!names.empty(), path, "no sources given for image '" + lines[i] + "'");
    if (names[0] == "__auto__") {
      int count = kDefaultAutoSources;
      if (names.size() > 1) {
        try {
          count = std::stoi(names[1]);
        } catch (const std::exception&) {
          throw Error(path,
                      "bad source count '" + names[1] + "' for image '" + lines[i] + "'");
        }
      }
      problem.source_image_ids = SelectSourceImages(reconstruction, problem.ref_image_id,
                                                    count, min_triangulation_angle);
    } else if (names[0] == "__all__") {
      for (const auto& [id, image] : reconstruction.images) {
        if (id != problem.ref_image_id) problem.source_image_ids.push_back(id);
      }
    } else {
      for (const std::string& name : names) {
        const uint32_t id = image_id(name);
        if (id != problem.ref_image_id) problem.source_image_ids.push_back(id);
      }
    }
    problems.push_back(problem);
  }
  return problems;
}

void WriteDefaultStereoConfigs(const std::string& stereo_dir,
                               const colmap::Reconstruction& reconstruction) {
  colmap::CreateDirectories(stereo_dir);
  const std::string patch_match = stereo_dir + "/patch-match.cfg";
  const std::string fusion = stereo_dir + "/fusion.cfg";
  std::error_code ec;
  if (!std::filesystem::exists(patch_match, ec)) {
    WriteFileAtomic(patch_match, [&](std::ostream& out) {
      for (const auto& [id, image] : reconstruction.images) {
        out << image.name << "\n__auto__, " << kDefaultAutoSources << "\n";
      }
    });
  }
  if (!std::filesystem::exists(fusion, ec)) {
    WriteFileAtomic(fusion, [&](std::ostream& out) {
      for (const auto& [id, image] : reconstruction.images) out << image.name << "\n";
    });
  }
}

}  // namespace fvs::mvs
