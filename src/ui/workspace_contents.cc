#include "ui/workspace_contents.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/geometry/ply.h"
#include "fvs/util/error.h"

namespace fvs::ui {
namespace {

namespace fs = std::filesystem;

bool HasModel(const fs::path& dir) {
  return fs::exists(dir / "cameras.bin") || fs::exists(dir / "cameras.txt");
}

// The display camera of an image; distorted models (a plain SfM model) are shown with
// their focal length and a centred principal point, which is all a frustum needs.
PinholeCamera DisplayCamera(const colmap::Reconstruction& model,
                            const colmap::Image& image) {
  try {
    return model.PinholeFor(image.image_id);
  } catch (const Error&) {
    const colmap::Camera& c = model.cameras.at(image.camera_id);
    PinholeCamera camera;
    camera.width = static_cast<int>(c.width);
    camera.height = static_cast<int>(c.height);
    camera.fx = camera.fy = c.params.empty() ? c.width : c.params[0];
    camera.cx = 0.5 * c.width;
    camera.cy = 0.5 * c.height;
    camera.R = image.Rotation();
    camera.t = image.tvec;
    return camera;
  }
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

}  // namespace

WorkspaceContents LoadWorkspace(const std::string& path) {
  Require(!path.empty(), "workspace", "no workspace folder given");
  Require(fs::is_directory(path), path, "no such workspace folder");
  WorkspaceContents w;
  w.path = path;
  const fs::path sparse = fs::path(path) / "sparse";
  if (HasModel(sparse)) {
    w.sparse_dir = sparse.string();
  } else if (HasModel(sparse / "0")) {
    w.sparse_dir = (sparse / "0").string();
  } else {
    throw Error(path,
                "no COLMAP sparse model in sparse/ or sparse/0/ (cameras.bin or "
                "cameras.txt); is this a COLMAP workspace?");
  }
  const colmap::Reconstruction model = colmap::ReadSparseModel(w.sparse_dir);
  model.Check(w.sparse_dir);
  Require(!model.images.empty(), w.sparse_dir, "the model has no registered images");

  // The prepared scene when there is a mesh; its origin is then the display origin too.
  const std::string mesh_path = colmap::DenseWorkspace(path).ProxyMeshPath();
  if (!fs::exists(mesh_path)) {
    w.render_error = mesh_path +
                     ": no proxy mesh, so nothing can be rendered (run colmap "
                     "view_synthesis_prepare on this workspace)";
  } else {
    try {
      w.scene = std::make_shared<const Scene>(Scene::Load(path));
    } catch (const std::exception& e) {
      w.render_error = e.what();
    }
  }

  std::vector<PinholeCamera> world_cameras;
  for (const auto& [id, image] : model.images) {
    w.view_names.push_back(image.name);
    world_cameras.push_back(DisplayCamera(model, image));
  }
  if (w.scene) {
    w.origin = w.scene->origin();
  } else {
    for (const PinholeCamera& c : world_cameras) w.origin += c.Center();
    w.origin /= static_cast<double>(world_cameras.size());
  }
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (PinholeCamera& c : world_cameras) {
    c.t += c.R * w.origin;  // to the scene frame
    up -= c.R.row(1).transpose();
    w.cameras.push_back(c);
  }
  if (up.norm() > 1e-9) w.up = up.normalized();

  w.points.reserve(model.points3D.size());
  w.point_colors.reserve(model.points3D.size());
  for (const auto& [id, point] : model.points3D) {
    if (!point.xyz.allFinite()) continue;
    w.points.push_back(point.xyz - w.origin);
    w.point_colors.emplace_back(point.color[0], point.color[1], point.color[2]);
  }

  if (w.scene) {
    w.mesh = w.scene->mesh();
  } else if (fs::exists(mesh_path)) {
    // The scene failed for another reason (a missing photo, say): still show the mesh.
    try {
      w.mesh = ReadPlyMesh(mesh_path);
      for (Eigen::Vector3d& x : w.mesh.vertices) x -= w.origin;
    } catch (const std::exception&) {
      w.mesh = TriangleMesh();
    }
  }

  // Scale: median distance of the points to their median, else the camera spread.
  std::vector<double> distances;
  for (const Eigen::Vector3d& p : w.points) distances.push_back(p.norm());
  for (const PinholeCamera& c : w.cameras) distances.push_back(c.Center().norm());
  const double scale = Median(distances);
  w.scale = std::isfinite(scale) && scale > 1e-9 ? scale : 1.0;
  return w;
}

int PickCamera(const std::vector<PinholeCamera>& cameras, const PinholeCamera& view,
               double x, double y, double max_pixels) {
  int best = -1;
  double best_distance = max_pixels;
  for (int i = 0; i < static_cast<int>(cameras.size()); ++i) {
    const Eigen::Vector3d xc = view.WorldToCamera(cameras[i].Center());
    if (xc.z() <= 1e-9) continue;
    const double d = (view.CameraToPixel(xc) - Eigen::Vector2d(x, y)).norm();
    if (d < best_distance) {
      best_distance = d;
      best = i;
    }
  }
  return best;
}

}  // namespace fvs::ui
