// The mesher's options, input checks and the dense-workspace reader (no CGAL here).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/geometry/ply.h"
#include "fvs/mvs/delaunay.h"
#include "fvs/mvs/isolated_points.h"
#include "fvs/util/check.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs::mvs {
namespace {

const char kWho[] = "delaunay mesher";

std::string Num(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Image ids of a COLMAP 3.8 images.bin in file order: uint64 count, then per image uint32
// id, 7 doubles (qvec, tvec), uint32 camera id, the name up to '\0', uint64 number of 2D
// points and 24 bytes per point.
std::vector<uint32_t> ReadImageIdsBinary(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  Require(file.good(), path, "cannot open");
  auto read = [&](void* data, size_t bytes) {
    file.read(static_cast<char*>(data), static_cast<std::streamsize>(bytes));
    Require(static_cast<size_t>(file.gcount()) == bytes, path, "truncated image record");
  };
  uint64_t count = 0;
  read(&count, sizeof(count));
  std::vector<uint32_t> ids;
  for (uint64_t i = 0; i < count; ++i) {
    uint32_t id = 0;
    read(&id, sizeof(id));
    ids.push_back(id);
    file.seekg(7 * sizeof(double) + sizeof(uint32_t), std::ios::cur);
    char c = 1;
    while (c != '\0') read(&c, 1);
    uint64_t num_points2D = 0;
    read(&num_points2D, sizeof(num_points2D));
    Require(num_points2D < (uint64_t{1} << 40), path, "implausible number of 2D points");
    file.seekg(static_cast<std::streamoff>(num_points2D * 24), std::ios::cur);
    Require(file.good(), path, "truncated image record");
  }
  return ids;
}

// images.txt: comment lines, then per image one pose line and one (possibly empty) line
// of 2D points, read as COLMAP reads them.
std::vector<uint32_t> ReadImageIdsText(const std::string& path) {
  std::ifstream file(path);
  Require(file.good(), path, "cannot open");
  std::vector<uint32_t> ids;
  std::string line;
  while (std::getline(file, line)) {
    line = TrimString(line);
    if (line.empty() || line[0] == '#') continue;
    std::istringstream tokens(line);
    long long id = -1;
    tokens >> id;
    Require(!tokens.fail() && id >= 0 && id <= 0xFFFFFFFFll, path,
            "bad image line '" + line.substr(0, 60) + "'");
    ids.push_back(static_cast<uint32_t>(id));
    std::getline(file, line);  // the 2D points
  }
  return ids;
}

// The names in a COLMAP fusion.cfg (one image name per line; blank lines skipped).
std::set<std::string> ReadFusionImageNames(const std::string& path) {
  std::error_code ec;
  // (A folder opens as a stream and reads as empty: no image would count as fused.)
  Require(std::filesystem::is_regular_file(path, ec), path, "is not a file");
  std::ifstream file(path);
  Require(file.good(), path, "cannot open");
  std::set<std::string> names;
  std::string line;
  while (std::getline(file, line)) {
    line = TrimString(line);
    if (!line.empty()) names.insert(line);
  }
  Require(!file.bad(), path, "read error");
  return names;
}

// Appends the SfM points of `reconstruction` that `options` admits, their visibility
// restricted to the fused images (positions in `order`).
void AppendSparsePoints(const colmap::Reconstruction& reconstruction,
                        const std::vector<uint32_t>& order,
                        const std::set<std::string>* fused_names,
                        const DelaunayMeshingOptions& options,
                        DelaunayMeshingInput* input) {
  if (options.sparse_min_track_length <= 0) return;
  std::map<uint32_t, uint32_t> index_of;  // image id -> position in `order`
  for (size_t i = 0; i < order.size(); ++i) {
    const std::string& name = reconstruction.images.at(order[i]).name;
    if (!fused_names || fused_names->count(name)) index_of[order[i]] = i;
  }
  for (const auto& [id, point] : reconstruction.points3D) {
    if (point.error > options.sparse_max_error || !point.xyz.allFinite()) continue;
    std::set<uint32_t> seen;  // a track may hold one image twice
    for (const colmap::TrackElement& el : point.track) {
      const auto it = index_of.find(el.image_id);
      if (it != index_of.end()) seen.insert(it->second);
    }
    if (static_cast<int>(seen.size()) < options.sparse_min_track_length) continue;
    input->points.push_back(point.xyz);
    input->visibility.emplace_back(seen.begin(), seen.end());
    ++input->num_sparse_points;
  }
}

}  // namespace

namespace {

// Every option that shapes the mesh (not num_threads).
std::string DescribeMeshing(const DelaunayMeshingOptions& o) {
  std::ostringstream s;
  s.precision(17);
  s << "proj=" << o.max_proj_dist << " depth=" << o.max_depth_dist
    << " visibility=" << o.visibility_sigma << " distance=" << o.distance_sigma_factor
    << " quality=" << o.quality_regularization << " side=" << o.max_side_length_factor
    << "@" << o.max_side_length_percentile << " isolated=" << o.isolated_point_neighbors
    << "x" << o.isolated_point_factor << " spacing=" << o.max_side_spacing_factor
    << " sparse=" << o.sparse_min_track_length << "@" << o.sparse_max_error;
  return s.str();
}

}  // namespace

std::string DelaunayMeshingOptions::ToString() const {
  // The defaults before session 29 (max_proj_dist 20, max_side_spacing_factor 10): the
  // fingerprint of the meshes made before the options reached prepare.
  DelaunayMeshingOptions legacy;
  legacy.max_proj_dist = 20.0;
  legacy.max_side_spacing_factor = 10.0;
  const std::string description = DescribeMeshing(*this);
  return description == DescribeMeshing(legacy) ? "" : description;
}

void DelaunayMeshingOptions::Check() const {
  auto require = [](bool ok, const std::string& what) { Require(ok, kWho, what); };
  require(std::isfinite(max_proj_dist) && max_proj_dist >= 0,
          "max_proj_dist must be >= 0, not " + Num(max_proj_dist));
  require(max_depth_dist >= 0 && max_depth_dist <= 1,
          "max_depth_dist must be in [0, 1], not " + Num(max_depth_dist));
  require(std::isfinite(visibility_sigma) && visibility_sigma > 0,
          "visibility_sigma must be > 0, not " + Num(visibility_sigma));
  require(std::isfinite(distance_sigma_factor) && distance_sigma_factor > 0,
          "distance_sigma_factor must be > 0, not " + Num(distance_sigma_factor));
  require(std::isfinite(quality_regularization) && quality_regularization >= 0,
          "quality_regularization must be >= 0, not " + Num(quality_regularization));
  require(std::isfinite(max_side_length_factor) && max_side_length_factor >= 0,
          "max_side_length_factor must be >= 0, not " + Num(max_side_length_factor));
  require(max_side_length_percentile >= 0 && max_side_length_percentile <= 100,
          "max_side_length_percentile must be in [0, 100], not " +
              Num(max_side_length_percentile));
  require(num_threads >= -1, "num_threads must be -1 (all), 0 (all) or positive");
  require(std::isfinite(max_side_spacing_factor) && max_side_spacing_factor >= 0,
          "max_side_spacing_factor must be >= 0, not " + Num(max_side_spacing_factor));
  require(sparse_min_track_length >= 0, "sparse_min_track_length must be >= 0, not " +
                                            std::to_string(sparse_min_track_length));
  require(std::isfinite(sparse_max_error) && sparse_max_error > 0,
          "sparse_max_error must be > 0, not " + Num(sparse_max_error));
  IsolatedPointOptions isolated;
  isolated.num_neighbors = isolated_point_neighbors;
  isolated.factor = isolated_point_factor;
  isolated.Check();
}

void DelaunayMeshingInput::Check() const {
  Require(!points.empty(), points_subject, "empty point cloud: nothing to mesh");
  Require(points.size() >= 4, points_subject,
          "only " + std::to_string(points.size()) +
              " points: a volume needs at least 4 (degenerate point cloud)");
  FVS_CHECK(num_sparse_points <= points.size(), "more SfM points than points");
  Require(visibility.size() == points.size(), visibility_subject,
          "has " + std::to_string(visibility.size()) +
              " points but the point cloud has " + std::to_string(points.size()) +
              " (the files do not belong together)");
  for (size_t k = 0; k < cameras.size(); ++k) {
    Require(cameras[k].IsValid(), kWho, "camera " + std::to_string(k) + " is not valid");
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw Error(points_subject, "point " + std::to_string(i) + " is not finite");
    }
    for (const uint32_t k : visibility[i]) {
      if (k >= cameras.size()) {
        throw Error(visibility_subject, "point " + std::to_string(i) +
                                            " is seen by image index " +
                                            std::to_string(k) + " but there are only " +
                                            std::to_string(cameras.size()) +
                                            " images (the files do not belong together)");
      }
    }
  }
}

std::string DelaunayMeshingStats::Summary() const {
  char buffer[512];
  std::snprintf(
      buffer, sizeof(buffer),
      "%zu points (%zu from SfM; %zu isolated dropped) -> %zu vertices, %zu cells, %zu "
      "rays (%.0f "
      "steps each), %zu surface facets -> %zu "
      "faces (%zu dropped by local spacing), %zu vertices; time %.2f s (triangulation "
      "%.2f, visibility %.2f, "
      "graph cut %.2f, extraction %.2f)",
      num_input_points, num_sparse_points, num_isolated_points, num_vertices, num_cells,
      num_rays, num_rays ? static_cast<double>(num_ray_steps) / num_rays : 0.0,
      num_surface_facets, num_faces, num_spacing_filtered, num_mesh_vertices,
      seconds_total, seconds_triangulation, seconds_visibility, seconds_graph,
      seconds_extraction);
  return buffer;
}

std::vector<uint32_t> ReadImageIdsInFileOrder(const std::string& sparse_dir) {
  const std::string bin = sparse_dir + "/images.bin";
  const std::string txt = sparse_dir + "/images.txt";
  if (std::filesystem::exists(bin)) return ReadImageIdsBinary(bin);
  if (std::filesystem::exists(txt)) return ReadImageIdsText(txt);
  throw Error(sparse_dir, "no images.bin or images.txt");
}

DelaunayMeshingInput ReadDenseMeshingInput(const std::string& workspace_path,
                                           const DelaunayMeshingOptions& options) {
  const colmap::DenseWorkspace workspace(workspace_path);
  const std::string fused = workspace.FusedPath();
  const std::string vis = workspace.FusedVisPath();
  Require(std::filesystem::exists(fused), fused,
          "missing (run stereo fusion first: colmap stereo_fusion)");
  Require(std::filesystem::exists(vis), vis, "missing (written by colmap stereo_fusion)");

  DelaunayMeshingInput input;
  input.points_subject = fused;
  input.visibility_subject = vis;
  PointCloud cloud = ReadPlyPointCloud(fused);
  Require(cloud.size() > 0, fused, "empty point cloud: nothing to mesh");
  input.points = std::move(cloud.points);
  input.visibility = colmap::ReadFusedVisibility(vis);
  Require(input.visibility.size() == input.points.size(), vis,
          "has " + std::to_string(input.visibility.size()) + " points but " + fused +
              " has " + std::to_string(input.points.size()) +
              " (the files do not belong together)");

  const colmap::Reconstruction reconstruction =
      colmap::ReadSparseModel(workspace.SparseDir());
  // COLMAP's fusion numbers images by their position in the model's image list, which is
  // the file order of images.bin/.txt (see delaunay.h).
  const std::vector<uint32_t> order = ReadImageIdsInFileOrder(workspace.SparseDir());
  Require(order.size() == reconstruction.images.size(), workspace.SparseDir(),
          "images file lists " + std::to_string(order.size()) +
              " images but the model has " +
              std::to_string(reconstruction.images.size()));
  input.cameras.reserve(order.size());
  for (const uint32_t id : order) input.cameras.push_back(reconstruction.PinholeFor(id));
  const std::string fusion_cfg = workspace.StereoDir() + "/fusion.cfg";
  // Without SfM points (COLMAP's fused-only input) fusion.cfg is not read at all.
  if (options.sparse_min_track_length > 0 && std::filesystem::exists(fusion_cfg)) {
    const std::set<std::string> fused_names = ReadFusionImageNames(fusion_cfg);
    AppendSparsePoints(reconstruction, order, &fused_names, options, &input);
  } else {
    AppendSparsePoints(reconstruction, order, nullptr, options, &input);
  }
  input.Check();
  return input;
}

DelaunayMeshingStats DenseDelaunayMeshing(const std::string& workspace_path,
                                          const std::string& output_path,
                                          const DelaunayMeshingOptions& options) {
  options.Check();
  Timer timer;
  const DelaunayMeshingInput input = ReadDenseMeshingInput(workspace_path, options);
  const double read_seconds = timer.Seconds();
  DelaunayMeshingStats stats;
  const TriangleMesh mesh = DelaunayMeshing(input, options, &stats);
  Require(!mesh.faces.empty(), input.points_subject,
          "the graph cut found no surface (every cell labelled " +
              std::string(stats.num_surface_facets == 0 ? "alike"
                                                        : "but only long-edge faces") +
              "): the points and visibility do not describe a surface");
  timer.Restart();
  WritePlyMesh(output_path, mesh);
  stats.seconds_total += read_seconds + timer.Seconds();
  return stats;
}

}  // namespace fvs::mvs
