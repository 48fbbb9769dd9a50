#include "fvs/controllers/render_settings.h"

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "colmap_ext/workspace.h"
#include "fvs/render/method.h"
#include "fvs/scene/photo_quality.h"
#include "fvs/util/hash.h"

namespace fvs {
namespace {

// The regular files below `folder` (or `folder` itself when a file), sorted; none when
// it does not exist.
std::vector<std::string> FilesBelow(const std::string& folder) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  std::error_code ec;
  if (fs::is_regular_file(folder, ec)) return {folder};
  for (auto it = fs::recursive_directory_iterator(folder, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file()) files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The target file and, for images.txt, the cameras.txt beside it.
std::string TargetsHash(const RenderTargetsOptions& o) {
  if (!o.camera_path.empty()) {
    return ContentHash({o.camera_path},
                       std::filesystem::path(o.camera_path).parent_path().string());
  }
  if (o.target_images.empty()) return "";
  const std::filesystem::path folder =
      std::filesystem::path(o.target_images).parent_path();
  return ContentHash({o.target_images, (folder / "cameras.txt").string()},
                     folder.string());
}

std::string TargetsKind(const RenderTargetsOptions& o) {
  if (!o.target_images.empty()) return "target_images";
  if (!o.camera_path.empty()) return "camera_path";
  if (o.orbit > 0) return "orbit " + std::to_string(o.orbit);
  return "interpolate " + std::to_string(o.interpolate);
}

}  // namespace

std::string ContentHash(const std::vector<std::string>& paths, const std::string& root) {
  uint64_t hash = 0;
  for (const std::string& path : paths) {
    for (const std::string& file : FilesBelow(path)) {
      const std::string name = std::filesystem::path(file).lexically_relative(root);
      hash = HashFile(file, Hash64(name.data(), name.size(), hash));
    }
  }
  return HexHash(hash);
}

std::string WorkspaceContentHash(const std::string& workspace_path) {
  const colmap::DenseWorkspace ws(workspace_path);
  // The photo quality report decides which sources rank last; absent, it adds nothing.
  return ContentHash({ws.SparseDir(), ws.ProxyMeshPath(), ws.ImagesDir(),
                      PhotoQualityPath(workspace_path)},
                     workspace_path);
}

std::string RenderSettingsJson(const RenderTargetsOptions& o) {
  nlohmann::json json;
  json["method"] = o.method;
  if (!o.render.model_path.empty()) {
    json["weights_hash"] = HexHash(HashFile(o.render.model_path));
  }
  json["workspace_hash"] = WorkspaceContentHash(o.workspace_path);
  json["num_sources"] = o.render.num_sources;
  if (o.render.num_sources == 0) json["max_num_sources"] = o.render.max_num_sources;
  json["selection_tolerance"] = o.render.selection_tolerance;
  json["warp_tolerance"] = o.render.warp_tolerance;
  json["width"] = o.width;
  json["height"] = o.height;
  json["scale"] = o.scale;
  json["holdout"] = o.holdout;
  json["source_hysteresis"] = o.render.source_hysteresis;
  json["stable_source_order"] = o.render.stable_source_order;
  json["temporal_blend"] = o.temporal.temporal_blend;
  json["fill_holes"] = o.render.fill_holes;
  if (o.render.use_blurry_sources) json["use_blurry_sources"] = true;
  if (o.method == "ulr" || o.method == "nearest") {
    json["interpolation"] = o.render.interpolation;
  }
  if (o.method == "ulr") {
    json["ulr_num_blend"] = o.render.ulr_num_blend;
    json["ulr_resolution_weight"] = o.render.ulr_resolution_weight;
  }
  // Tiles change the network's context at their seams.
  if (TraitsOfMethod(o.method).needs_weights) {
    json["precision"] = o.render.precision;
    json["tile_size"] = o.render.tile_size;
    json["tile_overlap"] = o.render.tile_overlap;
  }
  json["targets"] = TargetsKind(o);
  const std::string targets_hash = TargetsHash(o);
  if (!targets_hash.empty()) json["targets_hash"] = targets_hash;
  return json.dump(2) + "\n";
}

}  // namespace fvs
