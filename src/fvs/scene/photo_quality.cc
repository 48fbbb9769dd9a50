#include "fvs/scene/photo_quality.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

Image Grey(const Image& photo) {
  Image grey(photo.width, photo.height, 1);
  for (int y = 0; y < photo.height; ++y) {
    for (int x = 0; x < photo.width; ++x) {
      float sum = 0;
      for (int c = 0; c < photo.channels; ++c) sum += photo.at(x, y, c);
      const float v = sum / static_cast<float>(photo.channels);
      grey.at(x, y, 0) = std::isfinite(v) ? v : 0.0f;
    }
  }
  return grey;
}

}  // namespace

void PhotoQualityOptions::Check() const {
  Require(blur_ratio >= 0 && blur_ratio < 1, "--PhotoQuality.blur_ratio",
          "must be in [0, 1)");
  Require(duplicate_distance >= 0 && duplicate_distance < 1e3,
          "--PhotoQuality.duplicate_distance", "must be in [0, 1000)");
  Require(duplicate_degrees >= 0 && duplicate_degrees <= 180,
          "--PhotoQuality.duplicate_degrees", "must be in [0, 180]");
}

std::string PhotoQualityOptions::ToString() const {
  std::ostringstream out;
  out << "blur_ratio=" << blur_ratio << " duplicate_distance=" << duplicate_distance
      << " duplicate_degrees=" << duplicate_degrees;
  return out.str();
}

int PhotoQualityReport::num_blurry() const {
  return static_cast<int>(std::count_if(photos.begin(), photos.end(),
                                        [](const PhotoQuality& p) { return p.blurry; }));
}

int PhotoQualityReport::num_with_duplicates() const {
  return static_cast<int>(
      std::count_if(photos.begin(), photos.end(),
                    [](const PhotoQuality& p) { return !p.duplicates.empty(); }));
}

std::string PhotoQualityReport::Summary(int max_names) const {
  std::vector<const PhotoQuality*> blurry;
  for (const PhotoQuality& p : photos) {
    if (p.blurry) blurry.push_back(&p);
  }
  std::sort(blurry.begin(), blurry.end(),
            [](const PhotoQuality* a, const PhotoQuality* b) {
              return a->relative < b->relative;
            });
  std::ostringstream out;
  out << blurry.size() << " of " << photos.size() << " photos blurry";
  for (size_t i = 0; i < blurry.size() && static_cast<int>(i) < max_names; ++i) {
    out << (i ? ", " : ": ") << blurry[i]->name << " ("
        << static_cast<int>(std::lround(100 * blurry[i]->relative))
        << " % of the median)";
  }
  if (static_cast<int>(blurry.size()) > max_names) out << ", ...";
  if (!blurry.empty()) out << "; used as sources only where no sharp photo sees";
  int pairs = 0;
  std::string first;
  for (const PhotoQuality& p : photos) {
    for (const std::string& d : p.duplicates) {
      if (p.name < d) {
        if (++pairs == 1) first = p.name + " = " + d;
      }
    }
  }
  if (pairs > 0) {
    out << "; " << pairs << " near-duplicate pair" << (pairs > 1 ? "s" : "") << " ("
        << first << (pairs > 1 ? ", ..." : "") << ")";
  }
  return out.str();
}

double Sharpness(const Image& photo) {
  if (photo.width < 3 || photo.height < 3) return 0;
  Image grey = Grey(photo);
  if (std::max(grey.width, grey.height) > kSharpnessSize) {
    const auto [w, h] = ScaledSize(grey.width, grey.height, kSharpnessSize, 3);
    grey = ResizeArea(grey, w, h);
  }
  double sum = 0;
  for (int y = 1; y + 1 < grey.height; ++y) {
    for (int x = 1; x + 1 < grey.width; ++x) {
      const double laplacian = grey.at(x - 1, y, 0) + grey.at(x + 1, y, 0) +
                               grey.at(x, y - 1, 0) + grey.at(x, y + 1, 0) -
                               4.0 * grey.at(x, y, 0);
      sum += laplacian * laplacian;
    }
  }
  return sum / (static_cast<double>(grey.width - 2) * (grey.height - 2));
}

std::vector<std::pair<int, int>> NearDuplicatePairs(
    const std::vector<Eigen::Vector3d>& centres,
    const std::vector<Eigen::Vector3d>& directions, const PhotoQualityOptions& options) {
  const int n = static_cast<int>(centres.size());
  std::vector<double> nearest;
  for (int i = 0; i < n; ++i) {
    double best = INFINITY;
    for (int j = 0; j < n; ++j) {
      if (j != i) best = std::min(best, (centres[i] - centres[j]).norm());
    }
    if (std::isfinite(best)) nearest.push_back(best);
  }
  // The typical spacing of the shots; pairs at zero distance do not set it.
  std::vector<double> positive;
  for (double d : nearest) {
    if (d > 0) positive.push_back(d);
  }
  const double spacing = Median(positive);
  const double cos_limit = std::cos(options.duplicate_degrees * M_PI / 180.0);
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double distance = (centres[i] - centres[j]).norm();
      const bool close =
          spacing > 0 ? distance <= options.duplicate_distance * spacing : distance == 0;
      if (close && directions[i].dot(directions[j]) >= cos_limit) pairs.push_back({i, j});
    }
  }
  return pairs;
}

PhotoQualityReport MeasurePhotoQuality(const std::string& workspace_path,
                                       const PhotoQualityOptions& options) {
  options.Check();
  const colmap::DenseWorkspace ws(workspace_path);
  const colmap::Reconstruction rec = colmap::ReadSparseModel(ws.SparseDir());
  PhotoQualityReport report;
  std::vector<Eigen::Vector3d> centres, directions;
  std::vector<uint32_t> camera_ids;
  Progress progress("photo sharpness", static_cast<int>(rec.images.size()));
  for (const auto& [id, image] : rec.images) {
    PhotoQuality q;
    q.name = image.name;
    q.sharpness = Sharpness(colmap::ReadImage(JoinPaths(ws.ImagesDir(), image.name)));
    report.photos.push_back(q);
    camera_ids.push_back(image.camera_id);
    centres.push_back(image.ProjectionCenter());
    directions.push_back(image.Rotation().transpose() * Eigen::Vector3d::UnitZ());
    progress.Advance();
  }
  // Compared within each camera (a device, a size: detail per pixel differs between
  // them) where it took at least three photos, else with the whole set.
  std::vector<double> values;
  std::map<uint32_t, std::vector<double>> by_camera;
  for (size_t i = 0; i < report.photos.size(); ++i) {
    values.push_back(report.photos[i].sharpness);
    by_camera[camera_ids[i]].push_back(report.photos[i].sharpness);
  }
  report.median_sharpness = Median(values);
  for (size_t i = 0; i < report.photos.size(); ++i) {
    PhotoQuality& q = report.photos[i];
    const std::vector<double>& own = by_camera[camera_ids[i]];
    const double median = own.size() >= 3 ? Median(own) : report.median_sharpness;
    q.relative = median > 0 ? q.sharpness / median : 1;
    q.blurry = q.relative < options.blur_ratio;
  }
  for (const auto& [i, j] : NearDuplicatePairs(centres, directions, options)) {
    report.photos[i].duplicates.push_back(report.photos[j].name);
    report.photos[j].duplicates.push_back(report.photos[i].name);
  }
  return report;
}

std::string PhotoQualityPath(const std::string& workspace_path) {
  return colmap::DenseWorkspace(workspace_path).FvsDir() + "/photo_quality.json";
}

void WritePhotoQualityReport(const std::string& path, const PhotoQualityReport& report) {
  nlohmann::json json;
  json["median_sharpness"] = report.median_sharpness;
  json["summary"] = report.Summary();
  nlohmann::json photos = nlohmann::json::array();
  for (const PhotoQuality& p : report.photos) {
    photos.push_back({{"name", p.name},
                      {"sharpness", p.sharpness},
                      {"relative", p.relative},
                      {"blurry", p.blurry},
                      {"duplicates", p.duplicates}});
  }
  json["photos"] = photos;
  WriteFileAtomic(path, [&](std::ostream& out) { out << json.dump(2) << "\n"; });
}

PhotoQualityReport ReadPhotoQualityReport(const std::string& path) {
  PhotoQualityReport report;
  if (!std::filesystem::exists(path)) return report;
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileToString(path));
    report.median_sharpness = json.at("median_sharpness").get<double>();
    for (const nlohmann::json& p : json.at("photos")) {
      PhotoQuality q;
      q.name = p.at("name").get<std::string>();
      q.sharpness = p.at("sharpness").get<double>();
      q.relative = p.at("relative").get<double>();
      q.blurry = p.at("blurry").get<bool>();
      q.duplicates = p.at("duplicates").get<std::vector<std::string>>();
      report.photos.push_back(std::move(q));
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not a photo quality report: ") + e.what());
  }
  return report;
}

}  // namespace fvs
