#include "fvs/mvs/patch_match_stereo.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/mvs/stereo_config.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace fvs::mvs {
namespace {

namespace fs = std::filesystem;

bool Exists(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// The world points of the SfM model that `image_id` observes: support of its planar
// priors.
std::vector<Eigen::Vector3d> ObservedPoints(const colmap::Reconstruction& rec,
                                            uint32_t image_id) {
  std::vector<Eigen::Vector3d> points;
  const auto it = rec.images.find(image_id);
  if (it == rec.images.end()) return points;
  for (const colmap::Point2D& p : it->second.points2D) {
    if (p.point3D_id == colmap::kInvalidPoint3DId) continue;
    const auto point = rec.points3D.find(p.point3D_id);
    if (point != rec.points3D.end() && point->second.xyz.allFinite()) {
      points.push_back(point->second.xyz);
    }
  }
  return points;
}

// Whether the COLMAP array at `path` ("W&H&C&" header) is width x height: a map made at
// another --max_image_size is computed again rather than failing the geometric pass.
bool ArrayHasSize(const std::string& path, int width, int height) {
  std::ifstream in(path, std::ios::binary);
  char header[64] = {0};
  in.read(header, sizeof(header) - 1);
  int w = 0, h = 0, c = 0;
  return std::sscanf(header, "%d&%d&%d&", &w, &h, &c) == 3 && w == width && h == height;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() > suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Maps (those whose names end in one of `suffixes`) made with other settings than
// `stamp`, recorded in W/stereo/<stamp_file>, go before any is computed, and the stamp
// is written first: a run killed after this resumes with only the missing maps. A
// workspace without the file counts as stamped `unstamped` (the settings before the
// stamp existed).
void InvalidateStaleMaps(const colmap::DenseWorkspace& ws, const std::string& stamp_file,
                         const std::string& stamp, const std::string& unstamped,
                         const std::vector<std::string>& suffixes) {
  const std::string path = ws.StereoDir() + "/" + stamp_file;
  const std::string recorded = Exists(path) ? ReadText(path) : unstamped + "\n";
  if (recorded == stamp + "\n") return;
  for (const std::string dir : {"/depth_maps", "/normal_maps"}) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(ws.StereoDir() + dir, ec)) {
      const std::string name = entry.path().filename().string();
      for (const std::string& suffix : suffixes) {
        if (EndsWith(name, suffix)) fs::remove(entry.path(), ec);
      }
    }
  }
  WriteFileAtomic(path, [&](std::ostream& out) { out << stamp << "\n"; });
}

// The photometric settings added after workspaces existed; those workspaces hold maps
// made with window scale 1.
std::string PhotometricOptionsStamp(const PatchMatchOptions& options) {
  return "photometric max_window_scale=" + std::to_string(options.max_window_scale);
}

struct ViewSet {
  std::vector<StereoView> views;
  std::map<uint32_t, int> index_of;  // image id -> views index
};

}  // namespace

void PatchMatchStereoOptions::Check() const {
  patch_match.Check();
  const std::string s = "PatchMatchStereo";
  Require(max_image_size >= 0, s, "max_image_size must be >= 0 (0 = full size)");
  Require(max_image_size == 0 || max_image_size >= 16, s,
          "max_image_size must be 0 or at least 16");
  Require(max_num_sources >= 1 && max_num_sources <= 64, s,
          "max_num_sources must be in [1, 64]");
  Require(min_triangulation_angle >= 0 && min_triangulation_angle < 90, s,
          "min_triangulation_angle must be in [0, 90)");
  planar_prior.Check();
}

std::string GeometricOptionsStamp(const PatchMatchStereoOptions& options) {
  const PatchMatchOptions& p = options.patch_match;
  std::ostringstream s;
  s << "geometric iterations=" << p.num_geometric_iterations
    << " regularizer=" << p.geom_consistency_regularizer
    << " max_cost=" << p.geom_consistency_max_cost << " filter=" << p.filter
    << " ncc=" << p.filter_min_ncc << " angle=" << p.filter_min_triangulation_angle
    << " reprojection=" << p.filter_geom_consistency_max_cost
    << " consistent=" << p.filter_min_num_consistent
    << " sources=" << options.max_num_sources << " " << options.planar_prior.ToString();
  return s.str();
}

PatchMatchStereoSummary RunPatchMatchStereo(const std::string& workspace_path,
                                            const PatchMatchStereoOptions& options) {
  options.Check();
  Timer timer;
  PatchMatchStereoSummary summary;
  const colmap::DenseWorkspace ws(workspace_path);
  colmap::CheckDenseWorkspace(ws);
  const colmap::Reconstruction rec = colmap::ReadSparseModel(ws.SparseDir());
  rec.Check(ws.SparseDir());
  Require(rec.images.size() >= 2, ws.SparseDir(),
          "stereo needs at least 2 images, the sparse model has " +
              std::to_string(rec.images.size()));
  // Bad input leaves the workspace as it was: the default configs (written when missing,
  // as image_undistorter does) come only after the user's patch-match.cfg has parsed or,
  // without one, after every image the defaults would list has been found readable.
  const std::string cfg_path = ws.StereoDir() + "/patch-match.cfg";
  const bool had_config = Exists(cfg_path);
  std::vector<StereoProblem> problems;
  if (had_config) {
    problems = ReadPatchMatchConfig(cfg_path, rec, options.min_triangulation_angle);
  } else {
    for (const auto& [id, image] : rec.images) {
      const std::string path = ws.ImagePath(image.name);
      Require(Exists(path), path, "image file is missing (the sparse model lists it)");
      int width = 0, height = 0;
      colmap::ReadImageSize(path, &width, &height);  // throws for a file that is no image
    }
  }
  WriteDefaultStereoConfigs(ws.StereoDir(), rec);
  if (!had_config) {
    problems = ReadPatchMatchConfig(cfg_path, rec, options.min_triangulation_angle);
  }
  Require(!problems.empty(), cfg_path, "lists no images");
  summary.num_problems = static_cast<int>(problems.size());
  for (StereoProblem& p : problems) {
    if (static_cast<int>(p.source_image_ids.size()) > options.max_num_sources) {
      p.source_image_ids.resize(options.max_num_sources);
    }
  }

  // Every image involved, checked before any work: a missing file is one clear error.
  std::set<uint32_t> involved;
  for (const StereoProblem& p : problems) {
    involved.insert(p.ref_image_id);
    involved.insert(p.source_image_ids.begin(), p.source_image_ids.end());
  }
  for (uint32_t id : involved) {
    const std::string path = ws.ImagePath(rec.images.at(id).name);
    Require(Exists(path), path, "image file is missing (the sparse model lists it)");
  }
  ViewSet set;
  set.views.resize(involved.size());
  {
    std::vector<uint32_t> ids(involved.begin(), involved.end());
    for (size_t i = 0; i < ids.size(); ++i) set.index_of[ids[i]] = static_cast<int>(i);
    ParallelFor(
        0, static_cast<int64_t>(ids.size()),
        [&](int64_t i) {
          const colmap::Image& image = rec.images.at(ids[i]);
          const std::string path = ws.ImagePath(image.name);
          StereoView& view = set.views[i];
          view.name = image.name;
          PinholeCamera camera = rec.PinholeFor(image.image_id);
          Image grey = colmap::ReadImage(path, 1);
          Require(grey.width == camera.width && grey.height == camera.height, path,
                  "image is " + std::to_string(grey.width) + "x" +
                      std::to_string(grey.height) + " but its camera is " +
                      std::to_string(camera.width) + "x" + std::to_string(camera.height));
          if (options.max_image_size > 0 &&
              std::max(camera.width, camera.height) > options.max_image_size) {
            const auto [w, h] =
                ScaledSize(camera.width, camera.height, options.max_image_size, 2);
            grey = DownscaleGrey(grey, w, h);
            camera = camera.Resized(w, h);
          }
          view.camera = camera;
          view.grey = std::move(grey);
          if (!ComputeDepthRange(rec, image.image_id, &view.depth_min, &view.depth_max)) {
            view.depth_min = view.depth_max = 0;
          }
        },
        options.patch_match.num_threads);
  }
  colmap::CreateDirectories(ws.StereoDir() + "/depth_maps");
  colmap::CreateDirectories(ws.StereoDir() + "/normal_maps");

  auto sources_of = [&](const StereoProblem& p) {
    std::vector<int> sources;
    for (uint32_t id : p.source_image_ids) sources.push_back(set.index_of.at(id));
    return sources;
  };
  auto solvable = [&](const StereoProblem& p) {
    const StereoView& v = set.views[set.index_of.at(p.ref_image_id)];
    return !p.source_image_ids.empty() && v.depth_max > v.depth_min && v.depth_min > 0;
  };
  for (const StereoProblem& p : problems) {
    if (!solvable(p)) {
      ++summary.num_without_depth_range;
      std::cerr
          << "WARNING: " << rec.images.at(p.ref_image_id).name
          << ": no source views or no sparse points to bound its depth; no depth map"
          << std::endl;
    }
  }

  // Photometric pass. Geometric maps go with the photometric ones they were made from.
  PatchMatchOptions unstamped;
  unstamped.max_window_scale = 1;
  InvalidateStaleMaps(ws, "fvs_photometric_options.txt",
                      PhotometricOptionsStamp(options.patch_match),
                      PhotometricOptionsStamp(unstamped),
                      {".photometric.bin", ".geometric.bin"});
  const bool photometric_filter = !options.geom_consistency && options.patch_match.filter;
  PatchMatchOptions photometric_options = options.patch_match;
  photometric_options.filter = photometric_filter;
  std::set<uint32_t> recomputed;
  {
    Progress progress("PatchMatch photometric", summary.num_problems);
    for (const StereoProblem& p : problems) {
      const std::string& name = rec.images.at(p.ref_image_id).name;
      const std::string depth_path = ws.DepthMapPath(name, "photometric");
      const std::string normal_path = ws.NormalMapPath(name, "photometric");
      const PinholeCamera& working = set.views[set.index_of.at(p.ref_image_id)].camera;
      const bool current = Exists(depth_path) && Exists(normal_path) &&
                           ArrayHasSize(depth_path, working.width, working.height);
      if (solvable(p) && (options.overwrite || !current)) {
        const DepthNormalMap map =
            PatchMatchView(set.views, set.index_of.at(p.ref_image_id), sources_of(p),
                           photometric_options);
        colmap::WriteColmapArray(normal_path, map.normal);
        colmap::WriteColmapArray(depth_path, map.depth);
        recomputed.insert(p.ref_image_id);
        ++summary.num_photometric_computed;
      }
      progress.Advance();
    }
    progress.Finish();
  }

  // Geometric pass against the sources' photometric depth maps.
  if (options.geom_consistency) {
    std::map<uint32_t, Image> photometric_depths;
    auto photometric_depth = [&](uint32_t id) -> const Image& {
      auto it = photometric_depths.find(id);
      if (it != photometric_depths.end()) return it->second;
      const StereoView& view = set.views[set.index_of.at(id)];
      const std::string path = ws.DepthMapPath(view.name, "photometric");
      Image depth(view.camera.width, view.camera.height, 1);  // none: no consistency
      if (Exists(path)) {
        depth = colmap::ReadColmapArray(path);
        Require(
            depth.width == view.camera.width && depth.height == view.camera.height &&
                depth.channels == 1,
            path,
            "depth map size differs from the working image size (computed with another "
            "max_image_size?); rerun with --PatchMatchStereo.overwrite 1");
      }
      return photometric_depths.emplace(id, std::move(depth)).first->second;
    };
    InvalidateStaleMaps(ws, "fvs_geometric_options.txt", GeometricOptionsStamp(options),
                        "", {".geometric.bin"});
    Progress progress("PatchMatch geometric", summary.num_problems);
    for (const StereoProblem& p : problems) {
      const std::string& name = rec.images.at(p.ref_image_id).name;
      const std::string depth_path = ws.DepthMapPath(name, "geometric");
      const std::string normal_path = ws.NormalMapPath(name, "geometric");
      bool stale = recomputed.count(p.ref_image_id) > 0;
      for (uint32_t s : p.source_image_ids) stale = stale || recomputed.count(s) > 0;
      const bool missing = !Exists(depth_path) || !Exists(normal_path);
      if (solvable(p) && (options.overwrite || missing || stale)) {
        std::vector<const Image*> source_depths;
        for (uint32_t s : p.source_image_ids)
          source_depths.push_back(&photometric_depth(s));
        DepthNormalMap init;
        init.depth = photometric_depth(p.ref_image_id);
        init.normal = colmap::ReadColmapArray(ws.NormalMapPath(name, "photometric"));
        Require(init.normal.width == init.depth.width &&
                    init.normal.height == init.depth.height && init.normal.channels == 3,
                ws.NormalMapPath(name, "photometric"),
                "normal map does not match its depth map; rerun with "
                "--PatchMatchStereo.overwrite 1");
        DepthNormalMap map =
            PatchMatchView(set.views, set.index_of.at(p.ref_image_id), sources_of(p),
                           options.patch_match, &source_depths, &init);
        const PlanarPriorStats prior = FillFromPlanarPriors(
            set.views,
            {set.index_of.at(p.ref_image_id), sources_of(p), source_depths,
             ObservedPoints(rec, p.ref_image_id), &init.depth},
            options.planar_prior, &map);
        summary.planar_prior.empty += prior.empty;
        summary.planar_prior.candidates += prior.candidates;
        summary.planar_prior.filled += prior.filled;
        colmap::WriteColmapArray(normal_path, map.normal);
        colmap::WriteColmapArray(depth_path, map.depth);
        ++summary.num_geometric_computed;
      } else if (solvable(p) && !recomputed.count(p.ref_image_id)) {
        ++summary.num_skipped;
      }
      progress.Advance();
    }
    progress.Finish();
  } else {
    for (const StereoProblem& p : problems) {
      if (solvable(p) && !recomputed.count(p.ref_image_id)) ++summary.num_skipped;
    }
  }
  summary.seconds = timer.Seconds();
  return summary;
}

}  // namespace fvs::mvs
