#include "colmap_ext/workspace.h"

#include <filesystem>
#include <system_error>

#include "colmap_ext/reconstruction.h"
#include "fvs/util/error.h"

namespace fvs::colmap {

std::string DenseWorkspace::PreparedMeshPath() const {
  std::error_code ec;
  const std::string refined = RefinedMeshPath();
  return std::filesystem::is_regular_file(refined, ec) ? refined : DelaunayMeshPath();
}

std::string DenseWorkspace::ProxyMeshPath() const {
  namespace fs = std::filesystem;
  std::error_code ec, ec2;
  const std::string prepared = PreparedMeshPath(), scene = SceneRefinedMeshPath();
  if (!fs::is_regular_file(scene, ec)) return prepared;
  const auto scene_time = fs::last_write_time(scene, ec);
  const auto prepared_time = fs::last_write_time(prepared, ec2);
  return !ec && (ec2 || scene_time >= prepared_time) ? scene : prepared;
}

void CheckDenseWorkspace(const DenseWorkspace& workspace) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(workspace.root, ec)) {
    throw Error(workspace.root, "dense workspace folder does not exist");
  }
  if (!fs::is_directory(workspace.ImagesDir(), ec)) {
    throw Error(workspace.root,
                "not a COLMAP dense workspace: no images/ folder (run colmap "
                "image_undistorter first)");
  }
  const std::string sparse = workspace.SparseDir();
  const bool has_model = (fs::is_regular_file(sparse + "/cameras.bin", ec) &&
                          fs::is_regular_file(sparse + "/images.bin", ec)) ||
                         (fs::is_regular_file(sparse + "/cameras.txt", ec) &&
                          fs::is_regular_file(sparse + "/images.txt", ec));
  if (!has_model) {
    throw Error(workspace.root,
                "not a COLMAP dense workspace: no sparse model in sparse/ (cameras and "
                "images .bin or .txt)");
  }
}

void CheckWorkspaceImages(const DenseWorkspace& workspace,
                          const Reconstruction& reconstruction) {
  std::error_code ec;
  for (const auto& [id, image] : reconstruction.images) {
    const std::string path = workspace.ImagePath(image.name);
    if (!std::filesystem::is_regular_file(path, ec)) {
      throw Error(path, "image " + std::to_string(id) +
                            " of the sparse model is missing from the workspace");
    }
  }
}

void CreateDirectories(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec || !std::filesystem::is_directory(path)) {
    throw Error(path, "cannot create folder (" +
                          (ec ? ec.message() : std::string("a file is in the way")) +
                          ")");
  }
}

}  // namespace fvs::colmap
