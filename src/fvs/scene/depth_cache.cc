#include "fvs/scene/depth_cache.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs {

namespace fs = std::filesystem;

namespace {

nlohmann::json MeshStamp(const std::string& mesh_path) {
  std::error_code ec;
  const auto size = fs::file_size(mesh_path, ec);
  const auto mtime = fs::last_write_time(mesh_path, ec);
  nlohmann::json stamp;
  stamp["path"] = fs::path(mesh_path).filename().string();
  stamp["size"] = ec ? 0 : static_cast<uint64_t>(size);
  stamp["mtime"] = ec ? 0 : static_cast<int64_t>(mtime.time_since_epoch().count());
  return stamp;
}

}  // namespace

SourceDepthCache::SourceDepthCache(const std::string& workspace_path,
                                   const std::string& mesh_path,
                                   const std::string& backdrop_path, bool enabled)
    : root_(colmap::DenseWorkspace(workspace_path).FvsDir() + "/depth"),
      stamp_path_(root_ + "/stamp.json"),
      enabled_(enabled),
      mesh_stamp_(MeshStamp(mesh_path)) {
  if (fs::exists(backdrop_path)) backdrop_stamp_ = MeshStamp(backdrop_path);
  if (!enabled_ || !fs::exists(stamp_path_)) return;
  try {
    const nlohmann::json stamp = nlohmann::json::parse(ReadFileToString(stamp_path_));
    // A changed mesh or backdrop invalidates every depth (a stamp written before the
    // backdrop existed has none); a bad stamp file is treated as no cache.
    const nlohmann::json backdrop =
        stamp.contains("backdrop") ? stamp.at("backdrop") : nlohmann::json();
    if (stamp.at("mesh") == mesh_stamp_ && backdrop == backdrop_stamp_ &&
        stamp.at("views").is_object()) {
      views_ = stamp.at("views");
    }
  } catch (const std::exception&) {
    views_ = nlohmann::json::object();
  }
}

std::string SourceDepthCache::CameraStamp(const PinholeCamera& c) {
  std::string s = std::to_string(c.width) + " " + std::to_string(c.height);
  char buffer[32];
  auto add = [&](double x) {
    std::snprintf(buffer, sizeof(buffer), " %.17g", x);
    s += buffer;
  };
  for (double x : {c.fx, c.fy, c.cx, c.cy}) add(x);
  for (int i = 0; i < 9; ++i) add(c.R(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) add(c.t(i));
  return s;
}

std::shared_ptr<Image> SourceDepthCache::Find(const std::string& name,
                                              const PinholeCamera& world_camera) {
  if (!enabled_) return nullptr;
  const auto it = views_.find(name);
  if (it == views_.end() || *it != CameraStamp(world_camera)) return nullptr;
  const std::string path = root_ + "/" + name + ".bin";
  if (!fs::exists(path)) return nullptr;
  try {
    auto depth = std::make_shared<Image>(colmap::ReadColmapArray(path));
    if (depth->width != world_camera.width || depth->height != world_camera.height ||
        depth->channels != 1) {
      return nullptr;
    }
    for (float& d : depth->data) {
      if (!std::isfinite(d) || d < 0) d = 0;  // never trust a file with NaN
    }
    return depth;
  } catch (const Error&) {
    return nullptr;  // a damaged cache file is recomputed, not fatal
  }
}

void SourceDepthCache::Store(const std::string& name, const PinholeCamera& world_camera,
                             const Image& depth) {
  if (!enabled_) return;
  const std::string path = root_ + "/" + name + ".bin";
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  Require(!ec, fs::path(path).parent_path().string(),
          "cannot create folder: " + ec.message());
  colmap::WriteColmapArray(path, depth);
  views_[name] = CameraStamp(world_camera);
  dirty_ = true;
}

void SourceDepthCache::Commit() {
  if (!enabled_ || !dirty_) return;
  nlohmann::json stamp;
  stamp["mesh"] = mesh_stamp_;
  if (!backdrop_stamp_.is_null()) stamp["backdrop"] = backdrop_stamp_;
  stamp["views"] = views_;
  WriteFileAtomic(stamp_path_, [&](std::ostream& out) { out << stamp.dump(1) << "\n"; });
  dirty_ = false;
}

}  // namespace fvs
