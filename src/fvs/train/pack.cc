#include "fvs/train/pack.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fvs/scene/scene.h"
#include "fvs/scene/source_selection.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"
#include "fvs/util/safetensors.h"

namespace fvs {
namespace {

float Finite(float v) { return std::isfinite(v) ? v : 0.f; }

}  // namespace

void PackOptions::Check() const {
  Require(scale > 0 && scale <= 1 && std::isfinite(scale), "view_synthesis_pack",
          "--scale must be in (0, 1]");
  Require(depth_tolerance > 0 && std::isfinite(depth_tolerance), "view_synthesis_pack",
          "--depth_tolerance must be positive");
}


PackSummary PackScene(const Scene& scene, const PackOptions& options,
                      const std::string& output_dir) {
  options.Check();
  Timer timer;
  const int n = scene.num_views();
  const std::string subject = scene.workspace_path().empty()
                                  ? std::string("view_synthesis_pack")
                                  : scene.workspace_path();
  Require(n >= 2, subject,
          "a training scene needs at least 2 views, this one has " + std::to_string(n));
  // The most common size decides the packed size.
  std::map<std::pair<int, int>, int> sizes;
  for (const SceneView& v : scene.views()) ++sizes[{v.camera.width, v.camera.height}];
  const auto common = std::max_element(
      sizes.begin(), sizes.end(), [](auto& a, auto& b) { return a.second < b.second; });
  const int w = static_cast<int>(std::lround(common->first.first * options.scale));
  const int h = static_cast<int>(std::lround(common->first.second * options.scale));
  Require(w >= 16 && h >= 16, subject,
          "--scale " + std::to_string(options.scale) + " leaves images of " +
              std::to_string(w) + "x" + std::to_string(h) + " (at least 16x16 needed)");

  std::vector<PinholeCamera> cameras(n);
  std::vector<Image> depths(n);
  SafeTensor images{"images", SafeDtype::kU8, {n, 3, h, w}, {}};
  images.data.resize(static_cast<size_t>(n) * 3 * h * w);
  const size_t plane = static_cast<size_t>(h) * w;
  {
    Progress progress("packing views", n);
    // Views one at a time (RenderDepth and the photo reader parallelise inside).
    for (int i = 0; i < n; ++i) {
      cameras[i] = scene.view(i).camera.Resized(w, h);
      depths[i] = scene.RenderDepth(cameras[i]);
      for (float& d : depths[i].data) d = std::max(0.f, Finite(d));
      const Image& photo = scene.SourceImage(i);
      Require(photo.channels >= 3, scene.view(i).name, "the photo needs 3 channels");
      const Image small = ResizeArea(photo, w, h);
      uint8_t* dst = images.data.data() + static_cast<size_t>(i) * 3 * plane;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          for (int ch = 0; ch < 3; ++ch) {
            const float v = std::clamp(Finite(small.at(x, y, ch)), 0.f, 1.f);
            dst[ch * plane + static_cast<size_t>(y) * w + x] =
                static_cast<uint8_t>(std::lround(v * 255.f));
          }
        }
      }
      progress.Advance();
    }
  }

  std::vector<float> overlap(static_cast<size_t>(n) * n, 0.f);
  ParallelFor(
      0, static_cast<int64_t>(n) * n,
      [&](int64_t ij) {
        const int i = static_cast<int>(ij / n), j = static_cast<int>(ij % n);
        if (i == j) return;
        int64_t surface = 0;
        for (float d : depths[i].data) surface += d > 0;
        if (surface == 0) return;
        const int64_t count = CountVisibleTargetPixels(
            cameras[i], depths[i], cameras[j], depths[j], options.depth_tolerance);
        overlap[ij] = static_cast<float>(static_cast<double>(count) / surface);
      },
      options.num_threads);

  SafeTensorsFile file;
  file.Add(std::move(images));
  std::vector<float> depth_values;
  depth_values.reserve(static_cast<size_t>(n) * plane);
  for (const Image& d : depths)
    depth_values.insert(depth_values.end(), d.data.begin(), d.data.end());
  file.Add(SafeTensor::FromFloats("depths", {n, h, w}, depth_values.data()));
  file.Add(SafeTensor::FromFloats("overlap", {n, n}, overlap.data()));
  std::vector<double> k_values, r_values, t_values;
  nlohmann::json names = nlohmann::json::array();
  for (int i = 0; i < n; ++i) {
    const PinholeCamera& c = cameras[i];
    const Eigen::Matrix3d K = c.K();
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) {
        k_values.push_back(K(r, col));
        r_values.push_back(c.R(r, col));
      }
      t_values.push_back(c.t(r));
    }
    names.push_back(scene.view(i).name);
  }
  auto doubles = [](const std::string& name, std::vector<int64_t> shape,
                    const std::vector<double>& v) {
    SafeTensor t{name, SafeDtype::kF64, std::move(shape), {}};
    t.data.resize(v.size() * sizeof(double));
    std::memcpy(t.data.data(), v.data(), t.data.size());
    return t;
  };
  file.Add(doubles("K", {n, 3, 3}, k_values));
  file.Add(doubles("R", {n, 3, 3}, r_values));
  file.Add(doubles("t", {n, 3}, t_values));
  file.metadata["fvs_pack_version"] = std::to_string(kPackFormatVersion);
  file.metadata["names"] = names.dump();
  // Views held out of the geometry at prepare stay out of training and validation: they
  // are the views view_synthesis_eval reports.
  const std::string holdout_file = scene.workspace_path() + "/fvs/holdout.txt";
  if (std::filesystem::is_regular_file(holdout_file)) {
    nlohmann::json holdout = nlohmann::json::array();
    std::istringstream lines(ReadFileToString(holdout_file));
    for (std::string line; std::getline(lines, line);) {
      if (!line.empty()) holdout.push_back(line);
    }
    file.metadata["holdout"] = holdout.dump();
  }
  file.metadata["workspace"] = scene.workspace_path();
  file.metadata["scale"] = nlohmann::json(options.scale).dump();
  file.metadata["width"] = std::to_string(w);
  file.metadata["height"] = std::to_string(h);
  file.metadata["depth_tolerance"] = nlohmann::json(options.depth_tolerance).dump();
  file.metadata["origin"] =
      nlohmann::json({scene.origin().x(), scene.origin().y(), scene.origin().z()}).dump();

  // Not the throwing overload: its message is the library's, not "<folder>: <fault>".
  std::error_code ec;
  std::filesystem::create_directories(output_dir, ec);
  Require(!ec, output_dir, "cannot create the output folder: " + ec.message());
  PackSummary summary;
  summary.path = output_dir + "/" + kPackedSceneFile;
  WriteSafeTensors(summary.path, file);
  summary.num_views = n;
  summary.width = w;
  summary.height = h;
  double sum = 0;
  for (float v : overlap) sum += v;
  summary.mean_overlap = sum / std::max(1, n * (n - 1));
  summary.seconds = timer.Seconds();
  return summary;
}

}  // namespace fvs
