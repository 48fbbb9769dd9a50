#include "fvs/controllers/prepare_stages.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <sstream>

#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace fs = std::filesystem;

namespace {

bool IsImageExtension(std::string ext) {
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".tif" ||
         ext == ".heic" || ext == ".heif" || ext == ".tiff" || ext == ".bmp" ||
         ext == ".ppm" || ext == ".pgm";
}

}  // namespace

std::set<std::string> ParseHoldoutList(const std::string& spec) {
  std::set<std::string> names;
  if (spec.empty()) return names;
  std::error_code ec;
  if (fs::is_regular_file(spec, ec)) {
    std::istringstream lines(ReadFileToString(spec));
    std::string line;
    while (std::getline(lines, line)) {
      line = TrimString(line);
      if (!line.empty() && line[0] != '#') names.insert(line);
    }
    return names;
  }
  for (const std::string& part : SplitString(spec, ",")) {
    const std::string name = TrimString(part);
    if (!name.empty()) names.insert(name);
  }
  return names;
}

std::vector<std::string> ListImageFiles(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error(folder, "image folder does not exist");
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.is_regular_file() && IsImageExtension(entry.path().extension().string())) {
      names.push_back(entry.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  if (names.empty())
    throw Error(folder, "no images (.jpg, .png, .tif, ...) in this folder");
  return names;
}

bool LooksLikeVideoFrames(const std::vector<std::string>& names) {
  if (names.size() < 10) return false;
  // Strip the extension and the trailing digits: all the same prefix, numbers
  // consecutive.
  std::string prefix;
  long last = -1;
  int consecutive = 0;
  for (size_t i = 0; i < names.size(); ++i) {
    std::string stem = fs::path(names[i]).stem().string();
    size_t d = stem.size();
    while (d > 0 && std::isdigit(static_cast<unsigned char>(stem[d - 1]))) --d;
    if (d == stem.size()) return false;
    const std::string p = stem.substr(0, d);
    const long n = std::stol(stem.substr(d, 15));
    if (i == 0) prefix = p;
    if (p != prefix) return false;
    if (last >= 0 && n == last + 1) ++consecutive;
    last = n;
  }
  return consecutive >= static_cast<int>(names.size() * 9 / 10);
}

MatcherChoice ChooseMatcher(const std::vector<std::string>& names, bool gpu) {
  const size_t n = names.size();
  const size_t limit = gpu ? kMaxExhaustiveImagesGpu : kMaxExhaustiveImages;
  const std::string count = std::to_string(n) + " images";
  if (n <= limit) {
    return {"exhaustive",
            count + ", at most " + std::to_string(limit) + ": every pair is matched"};
  }
  if (LooksLikeVideoFrames(names)) {
    return {"sequential", count + " numbered as consecutive video frames, over " +
                              std::to_string(limit) + ": sequential with loop closure"};
  }
  return {"exhaustive",
          count + " over " + std::to_string(limit) +
              ", not consecutive frames: every pair is matched (" +
              std::to_string(n * (n - 1) / 2) +
              " pairs; --Matching.type sequential is far cheaper for video frames)"};
}

std::vector<std::pair<int, int>> SequentialPairs(int n, int overlap) {
  std::set<std::pair<int, int>> pairs;
  if (n < 2) return {};
  for (int i = 0; i < n; ++i) {
    for (int k = 1; k <= overlap && i + k < n; ++k) pairs.insert({i, i + k});
    int step = 1;
    for (int k = 0; k < overlap && i + step < n; ++k, step *= 2)
      pairs.insert({i, i + step});
  }
  const int every = std::max(5, (n + 49) / 50);
  std::vector<int> keyframes;
  for (int i = 0; i < n; i += every) keyframes.push_back(i);
  if (keyframes.back() != n - 1) keyframes.push_back(n - 1);
  for (size_t a = 0; a < keyframes.size(); ++a) {
    for (size_t b = a + 1; b < keyframes.size(); ++b) {
      pairs.insert({keyframes[a], keyframes[b]});
    }
  }
  return {pairs.begin(), pairs.end()};
}

bool ShouldRetryExhaustive(const std::string& matcher, int registered, int total) {
  return matcher != "exhaustive" && registered < total;
}

void WriteStereoConfigs(const std::string& workspace_path,
                        const std::set<std::string>& holdout, int max_sources) {
  const colmap::DenseWorkspace ws(workspace_path);
  const colmap::Reconstruction rec = colmap::ReadSparseModel(ws.SparseDir());
  // Shared 3D points between image pairs rank the sources, as COLMAP's __auto__ does.
  std::map<uint32_t, std::map<uint32_t, int>> shared;
  for (const auto& [id, point] : rec.points3D) {
    std::set<uint32_t> images;
    for (const auto& el : point.track) images.insert(el.image_id);
    for (uint32_t a : images) {
      for (uint32_t b : images) {
        if (a != b) ++shared[a][b];
      }
    }
  }
  std::ostringstream patch_match, fusion;
  for (const auto& [id, image] : rec.images) {
    if (holdout.count(image.name)) continue;
    std::vector<std::pair<int, uint32_t>> ranked;
    for (const auto& [other, count] : shared[id]) {
      if (!holdout.count(rec.images.at(other).name)) ranked.push_back({-count, other});
    }
    std::sort(ranked.begin(), ranked.end());
    if (ranked.empty()) continue;  // sees nothing in common: no depth map possible
    patch_match << image.name << "\n";
    for (size_t i = 0; i < ranked.size() && static_cast<int>(i) < max_sources; ++i) {
      patch_match << (i ? ", " : "") << rec.images.at(ranked[i].second).name;
    }
    patch_match << "\n";
    fusion << image.name << "\n";
  }
  colmap::CreateDirectories(ws.StereoDir());
  WriteFileAtomic(ws.StereoDir() + "/patch-match.cfg",
                  [&](std::ostream& out) { out << patch_match.str(); });
  WriteFileAtomic(ws.StereoDir() + "/fusion.cfg",
                  [&](std::ostream& out) { out << fusion.str(); });
}

std::vector<std::string> ShrunkenUndistortionWarnings(
    const colmap::Reconstruction& sfm, const colmap::Reconstruction& undistorted,
    int max_image_size) {
  std::vector<std::string> warnings;
  for (const auto& [id, camera] : undistorted.cameras) {
    const auto it = sfm.cameras.find(id);
    if (it == sfm.cameras.end()) continue;
    const double before =
        static_cast<double>(std::max(it->second.width, it->second.height));
    const double expected =
        max_image_size > 0 ? std::min<double>(before, max_image_size) : before;
    const double after = static_cast<double>(std::max(camera.width, camera.height));
    if (expected > 0 && after < 0.5 * expected) {
      warnings.push_back(
          "undistortion shrank camera " + std::to_string(id) + " from " +
          std::to_string(it->second.width) + "x" + std::to_string(it->second.height) +
          " to " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
          ": its distortion estimate cannot be undone at the image borders; try "
          "--ImageReader.camera_model OPENCV (or PINHOLE for undistorted photos)");
    }
  }
  return warnings;
}

}  // namespace fvs
