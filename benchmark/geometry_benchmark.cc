// How much of the photos a prepared workspace's geometry covers, and how right it is
// where the truth is known (issue 39, doc/real_scenes.md). Per registered view:
//   photometric, geometric  fraction of pixels with depth in W/stereo/depth_maps
//   mesh                    fraction with a surface in the mesh's depth (W/fvs/depth)
// and with --truth_path (a folder holding ground_truth/depth_maps/<name>.bin, as
// view_synthesis_synthetic writes it, in the workspace's frame): the share of the
// geometric map's and the mesh's pixels within 1 % and 5 % of the true depth and their
// median relative error. With --baseline_path (the same photos prepared before a change)
// the same shares for the pixels newly covered: with depth here, none there. With
// --reference_model (a COLMAP model of the same photos with known cameras, e.g. the
// published Middlebury calibration in ../shared/datasets/<scene>/sparse/0): the cameras
// of W/sparse after the best similarity onto it, as centre error relative to the
// reference cameras' extent and rotation error in degrees.
//
//   geometry_benchmark --workspace_path W [--truth_path T] [--baseline_path W0]
//                      [--reference_model M] [--output_path report.json]
//
// Prints one summary line per measure and writes every view's numbers as JSON.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "colmap_ext/dense_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/scene/mesh_coverage.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/image.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;

const char* kUsage =
    "usage: geometry_benchmark --workspace_path W [--truth_path T] [--baseline_path W0]\n"
    "                          [--reference_model M] [--output_path report.json]";

// Nearest pixel of `map` for pixel (x, y) of an image of size (width, height): stereo
// maps may be smaller than the photo (--Stereo.max_image_size).
float Sample(const Image& map, int x, int y, int width, int height) {
  const int mx = std::min(map.width - 1, static_cast<int>((x + 0.5) * map.width / width));
  const int my =
      std::min(map.height - 1, static_cast<int>((y + 0.5) * map.height / height));
  return map.data[static_cast<size_t>(my) * map.width + mx];
}

// Relative depth errors of the pixels of `depth` with a surface, against `truth` (at the
// truth's resolution), split into all pixels and those without one in `baseline`.
struct ErrorSample {
  std::vector<double> all, fresh;
};

void CollectErrors(const Image& depth, const Image& truth, const Image* baseline,
                   ErrorSample* out) {
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      const float d = Sample(depth, x, y, truth.width, truth.height);
      const float t = truth.data[static_cast<size_t>(y) * truth.width + x];
      if (!(d > 0 && std::isfinite(d)) || !(t > 0 && std::isfinite(t))) continue;
      const double err = std::abs(d - t) / t;
      out->all.push_back(err);
      if (baseline && baseline->width > 0) {
        const float b = Sample(*baseline, x, y, truth.width, truth.height);
        if (!(b > 0 && std::isfinite(b))) out->fresh.push_back(err);
      }
    }
  }
}

nlohmann::json Summarize(std::vector<double> errors) {
  nlohmann::json j;
  j["pixels"] = errors.size();
  if (errors.empty()) return j;
  size_t within1 = 0, within5 = 0;
  for (double e : errors) {
    within1 += e <= 0.01;
    within5 += e <= 0.05;
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  j["within_1pct"] = static_cast<double>(within1) / errors.size();
  j["within_5pct"] = static_cast<double>(within5) / errors.size();
  j["median_rel_error"] = errors[errors.size() / 2];
  return j;
}

Image ReadIfExists(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Image();
  return colmap::ReadColmapArray(path);
}

std::set<std::string> ReadHoldout(const std::string& workspace) {
  std::set<std::string> names;
  std::ifstream in(workspace + "/fvs/holdout.txt");
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) names.insert(line);
  }
  return names;
}

struct Accumulator {
  double sum = 0;
  double least = 2;
  std::string least_name;
  int count = 0;
  void Add(double f, const std::string& name) {
    sum += f;
    ++count;
    if (f < least) least = f, least_name = name;
  }
  nlohmann::json Json() const {
    nlohmann::json j;
    j["mean"] = count ? sum / count : 0.0;
    j["least"] = count ? least : 0.0;
    j["least_view"] = least_name;
    j["views"] = count;
    return j;
  }
};

// The workspace's cameras against a reference model of the same photos (matched by
// name), after the similarity that maps the estimated centres onto the reference ones.
nlohmann::json CompareCameras(const std::string& sparse_dir,
                              const std::string& reference_dir) {
  const colmap::Reconstruction est = colmap::ReadSparseModel(sparse_dir);
  const colmap::Reconstruction ref = colmap::ReadSparseModel(reference_dir);
  std::map<std::string, const colmap::Image*> by_name;
  for (const auto& [id, image] : ref.images) by_name[image.name] = &image;
  std::vector<const colmap::Image*> e, r;
  for (const auto& [id, image] : est.images) {
    const auto it = by_name.find(image.name);
    if (it != by_name.end()) e.push_back(&image), r.push_back(it->second);
  }
  nlohmann::json j;
  j["matched"] = e.size();
  j["reference_images"] = ref.images.size();
  if (e.size() < 3) return j;
  Eigen::Matrix3Xd src(3, e.size()), dst(3, e.size());
  for (size_t i = 0; i < e.size(); ++i) {
    src.col(i) = e[i]->ProjectionCenter();
    dst.col(i) = r[i]->ProjectionCenter();
  }
  const Eigen::Matrix4d sim = Eigen::umeyama(src, dst, true);
  const double scale = sim.block<3, 1>(0, 0).norm();
  const Eigen::Matrix3d rotation = sim.block<3, 3>(0, 0) / scale;
  const double extent = (dst.rowwise().maxCoeff() - dst.rowwise().minCoeff()).norm();
  std::vector<double> centre, angle;
  for (size_t i = 0; i < e.size(); ++i) {
    const Eigen::Vector3d c = (sim * src.col(i).homogeneous()).head<3>();
    centre.push_back((c - dst.col(i)).norm() / extent);
    // World-to-camera rotations: est R_e maps the aligned world by R_e * rotation^T.
    const Eigen::Matrix3d diff =
        r[i]->Rotation() * (e[i]->Rotation() * rotation.transpose()).transpose();
    angle.push_back(Eigen::AngleAxisd(diff).angle() * 180.0 / 3.14159265358979323846);
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  j["centre_error_median"] = median(centre);
  j["centre_error_max"] = *std::max_element(centre.begin(), centre.end());
  j["rotation_error_median_deg"] = median(angle);
  j["rotation_error_max_deg"] = *std::max_element(angle.begin(), angle.end());
  return j;
}

int Run(int argc, char** argv) {
  benchmark::CheckArgs(
      argc, argv, kUsage,
      {"--workspace_path", "--truth_path", "--baseline_path", "--output_path",
       "--reference_model"});
  std::map<std::string, std::string> args;
  for (int i = 1; i + 1 < argc; i += 2) args[argv[i]] = argv[i + 1];
  if (!args.count("--workspace_path")) {
    std::fprintf(stderr, "ERROR: --workspace_path is required\n%s\n", kUsage);
    return 2;
  }
  const std::string workspace = args["--workspace_path"];
  const std::string truth_root = args.count("--truth_path") ? args["--truth_path"] : "";
  const std::string baseline_root =
      args.count("--baseline_path") ? args["--baseline_path"] : "";
  const colmap::DenseWorkspace ws(workspace);
  const colmap::DenseWorkspace base(baseline_root);
  const std::set<std::string> holdout = ReadHoldout(workspace);

  const Scene scene = Scene::Load(workspace);
  std::unique_ptr<Scene> baseline_scene;
  if (!baseline_root.empty()) {
    baseline_scene = std::make_unique<Scene>(Scene::Load(baseline_root));
  }
  Accumulator photometric, geometric, mesh, mesh_held_out, with_backdrop;
  const bool has_backdrop = !scene.backdrop().faces.empty();
  ErrorSample stereo_errors, mesh_errors;
  nlohmann::json views = nlohmann::json::object();
  for (int i = 0; i < scene.num_views(); ++i) {
    const std::string& name = scene.view(i).name;
    nlohmann::json v;
    // The source depths hold the backdrop too (scene/backdrop.h): the mesh alone here.
    const Image mesh_depth =
        has_backdrop ? scene.RenderMeshDepth(scene.view(i).camera) : scene.SourceDepth(i);
    const double mesh_fraction = SurfaceFraction(mesh_depth);
    v["mesh"] = mesh_fraction;
    v["mesh_and_backdrop"] = SurfaceFraction(scene.SourceDepth(i));
    v["held_out"] = holdout.count(name) > 0;
    if (holdout.count(name)) {
      mesh_held_out.Add(mesh_fraction, name);
      views[name] = v;
      continue;
    }
    mesh.Add(mesh_fraction, name);
    with_backdrop.Add(v["mesh_and_backdrop"].get<double>(), name);
    const Image photo = ReadIfExists(ws.DepthMapPath(name, "photometric"));
    const Image geo = ReadIfExists(ws.DepthMapPath(name, "geometric"));
    if (photo.width > 0) photometric.Add(SurfaceFraction(photo), name);
    if (geo.width > 0) geometric.Add(SurfaceFraction(geo), name);
    v["photometric"] = photo.width > 0 ? SurfaceFraction(photo) : 0.0;
    v["geometric"] = geo.width > 0 ? SurfaceFraction(geo) : 0.0;
    if (!truth_root.empty()) {
      const Image truth =
          ReadIfExists(truth_root + "/ground_truth/depth_maps/" + name + ".bin");
      Require(truth.width > 0, truth_root, "no ground-truth depth map for " + name);
      Image base_geo, base_mesh;
      if (baseline_scene) {
        base_geo = ReadIfExists(base.DepthMapPath(name, "geometric"));
        const int j = baseline_scene->FindView(name);
        if (j >= 0) base_mesh = baseline_scene->RenderMeshDepth(baseline_scene->view(j).camera);
      }
      ErrorSample view_stereo, view_mesh;
      if (geo.width > 0) {
        CollectErrors(geo, truth, baseline_scene ? &base_geo : nullptr, &view_stereo);
      }
      CollectErrors(mesh_depth, truth, baseline_scene ? &base_mesh : nullptr,
                    &view_mesh);
      v["geometric_error"] = Summarize(view_stereo.all);
      v["mesh_error"] = Summarize(view_mesh.all);
      for (ErrorSample* s : {&view_stereo, &view_mesh}) {
        ErrorSample* total = s == &view_stereo ? &stereo_errors : &mesh_errors;
        total->all.insert(total->all.end(), s->all.begin(), s->all.end());
        total->fresh.insert(total->fresh.end(), s->fresh.begin(), s->fresh.end());
      }
    }
    views[name] = v;
  }
  nlohmann::json report;
  report["workspace"] = workspace;
  report["photometric"] = photometric.Json();
  report["geometric"] = geometric.Json();
  report["mesh"] = mesh.Json();
  report["mesh_held_out"] = mesh_held_out.Json();
  report["mesh_and_backdrop"] = with_backdrop.Json();
  auto line = [](const char* what, const Accumulator& a) {
    if (a.count == 0) return;
    std::printf("%-22s mean %5.1f %%  least %5.1f %% (%s), %d views\n", what,
                100 * a.sum / a.count, 100 * a.least, a.least_name.c_str(), a.count);
  };
  line("photometric maps", photometric);
  line("geometric maps", geometric);
  line("mesh", mesh);
  line("mesh, held-out views", mesh_held_out);
  if (has_backdrop) line("mesh and backdrop", with_backdrop);
  if (!truth_root.empty()) {
    report["geometric_error"] = Summarize(stereo_errors.all);
    report["mesh_error"] = Summarize(mesh_errors.all);
    if (baseline_scene) {
      report["geometric_error_new"] = Summarize(stereo_errors.fresh);
      report["mesh_error_new"] = Summarize(mesh_errors.fresh);
    }
    for (const char* key :
         {"geometric_error", "mesh_error", "geometric_error_new", "mesh_error_new"}) {
      if (!report.contains(key)) continue;
      const nlohmann::json& e = report[key];
      if (e["pixels"].get<size_t>() == 0) {
        std::printf("%-22s no pixels\n", key);
        continue;
      }
      std::printf(
          "%-22s %zu px: %5.1f %% within 1 %%, %5.1f %% within 5 %%, median %.4f\n", key,
          e["pixels"].get<size_t>(), 100 * e["within_1pct"].get<double>(),
          100 * e["within_5pct"].get<double>(), e["median_rel_error"].get<double>());
    }
  }
  if (args.count("--reference_model")) {
    const nlohmann::json c = CompareCameras(ws.SparseDir(), args["--reference_model"]);
    report["cameras"] = c;
    if (c.contains("centre_error_median")) {
      std::printf(
          "%-22s %d of %d matched: centre error median %.4f, max %.4f of the "
          "cameras' extent; rotation median %.3f, max %.3f deg\n",
          "cameras vs reference", c["matched"].get<int>(),
          c["reference_images"].get<int>(), c["centre_error_median"].get<double>(),
          c["centre_error_max"].get<double>(),
          c["rotation_error_median_deg"].get<double>(),
          c["rotation_error_max_deg"].get<double>());
    } else {
      std::printf("cameras vs reference    only %d images matched by name\n",
                  c["matched"].get<int>());
    }
  }
  report["views"] = views;
  if (args.count("--output_path")) {
    std::ofstream out(args["--output_path"]);
    out << report.dump(1) << "\n";
    Require(static_cast<bool>(out), args["--output_path"], "cannot write the report");
  }
  return 0;
}

}  // namespace
}  // namespace fvs

int main(int argc, char** argv) {
  try {
    return fvs::Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
}
