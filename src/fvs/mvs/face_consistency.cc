#include "fvs/mvs/face_consistency.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fvs/geometry/rasterizer.h"
#include "fvs/geometry/warp.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace fvs::mvs {
namespace {

const char kWho[] = "face consistency";

// A photo at the working size with the mesh rendered into it.
struct WorkingView {
  PinholeCamera camera;
  Image colour;                   // box-blurred by one pixel
  Image depth;                    // the mesh's, 0 where none
  std::vector<int32_t> face_ids;  // -1 where none
};

WorkingView MakeWorkingView(const FaceConsistencyView& view, const TriangleMesh& mesh,
                            int max_size) {
  const PinholeCamera& c = view.camera;
  Require(view.photo.channels == 3, kWho, "every photo must have 3 channels");
  const auto [w, h] = ScaledSize(c.width, c.height, max_size);
  WorkingView out;
  out.camera = c.Resized(w, h);
  out.colour = BoxBlur(ResizeArea(view.photo, w, h), 1);
  RasterizeOptions raster;
  raster.compute_face_ids = true;
  raster.num_threads = 1;  // the caller runs views in parallel
  RasterResult r = Rasterize(mesh, out.camera, raster);
  out.depth = std::move(r.depth);
  out.face_ids = std::move(r.face_ids);
  return out;
}

// The num_neighbors views nearest to each view among those looking within 60 degrees of
// it.
std::vector<std::vector<int>> Neighbours(const std::vector<WorkingView>& views,
                                         int count) {
  const int n = static_cast<int>(views.size());
  const double min_cos = std::cos(60.0 * M_PI / 180.0);
  std::vector<std::vector<int>> out(n);
  for (int i = 0; i < n; ++i) {
    std::vector<std::pair<double, int>> candidates;
    const Eigen::Vector3d ci = views[i].camera.Center();
    const Eigen::Vector3d di = views[i].camera.ViewDirection();
    for (int j = 0; j < n; ++j) {
      if (j == i || di.dot(views[j].camera.ViewDirection()) < min_cos) continue;
      const double d = (views[j].camera.Center() - ci).norm();
      if (std::isfinite(d)) candidates.emplace_back(d, j);
    }
    std::sort(candidates.begin(), candidates.end());
    for (int k = 0; k < std::min<int>(count, candidates.size()); ++k)
      out[i].push_back(candidates[k].second);
  }
  return out;
}

float DepthAt(const WorkingView& v, const Eigen::Vector2d& p) {
  const int x = static_cast<int>(std::floor(p.x())),
            y = static_cast<int>(std::floor(p.y()));
  if (x < 0 || y < 0 || x >= v.depth.width || y >= v.depth.height) return 0.f;
  return v.depth.data[static_cast<size_t>(y) * v.depth.width + x];
}

// Adds view i's pixel pairs with its neighbours to the per-face sums.
void AccumulateView(const std::vector<WorkingView>& views, int i,
                    const std::vector<int>& neighbours, double tolerance,
                    std::vector<double>* sum, std::vector<size_t>* count) {
  const WorkingView& ref = views[i];
  const int w = ref.depth.width, h = ref.depth.height;
  float colour[3];
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t pixel = static_cast<size_t>(y) * w + x;
      const int32_t face = ref.face_ids[pixel];
      const float d = ref.depth.data[pixel];
      if (face < 0 || !(d > 0) || !std::isfinite(d)) continue;
      const Eigen::Vector3d point = ref.camera.Unproject(x + 0.5, y + 0.5, d);
      if (!point.allFinite()) continue;
      const float* c = ref.colour.data.data() + ref.colour.Index(x, y);
      for (const int j : neighbours) {
        const WorkingView& other = views[j];
        const Eigen::Vector3d pc = other.camera.WorldToCamera(point);
        if (!(pc.z() > 0)) continue;
        const Eigen::Vector2d p = other.camera.CameraToPixel(pc);
        if (!p.allFinite() || p.x() < 0 || p.y() < 0 || p.x() >= other.depth.width ||
            p.y() >= other.depth.height) {
          continue;
        }
        const float dj = DepthAt(other, p);
        if (!(dj > 0) || std::abs(dj - pc.z()) > tolerance * pc.z()) continue;
        SampleBilinear(other.colour, p.x(), p.y(), colour, true);
        const double diff = (std::abs(c[0] - colour[0]) + std::abs(c[1] - colour[1]) +
                             std::abs(c[2] - colour[2])) /
                            3.0;
        if (!std::isfinite(diff)) continue;
        (*sum)[face] += diff;
        ++(*count)[face];
      }
    }
  }
}

}  // namespace

void FaceConsistencyOptions::Check() const {
  Require(max_image_size >= 16, kWho, "max_image_size must be at least 16");
  Require(num_neighbors >= 1, kWho, "num_neighbors must be at least 1");
  Require(std::isfinite(depth_tolerance) && depth_tolerance > 0 && depth_tolerance < 1,
          kWho, "depth_tolerance must be in (0, 1)");
  Require(std::isfinite(max_colour_difference) && max_colour_difference > 0, kWho,
          "max_colour_difference must be positive");
  Require(min_samples >= 1, kWho, "min_samples must be at least 1");
}

std::string FaceConsistencyOptions::ToString() const {
  if (!enabled) return "consistency=0";
  std::ostringstream s;
  s.precision(17);
  s << "consistency=1 size=" << max_image_size << " neighbours=" << num_neighbors
    << " depth=" << depth_tolerance << " difference=" << max_colour_difference
    << " samples=" << min_samples;
  return s.str();
}

std::string FaceConsistencyResult::Summary() const {
  std::ostringstream s;
  s.precision(3);
  s << "face consistency: removed " << num_removed << " of " << num_faces << " faces ("
    << num_judged << " judged, median difference " << median_difference << "; "
    << 100.0 * removed_area_share << " % of the judged pixels)";
  return s.str();
}

FaceDifferences MeasureFaceDifferences(const std::vector<FaceConsistencyView>& views,
                                       const TriangleMesh& mesh,
                                       const FaceConsistencyOptions& options) {
  options.Check();
  const int n = static_cast<int>(views.size());
  std::vector<WorkingView> working(n);
  Progress progress("face consistency", 2 * static_cast<int64_t>(n));
  ParallelFor(
      0, n,
      [&](int64_t i) {
        working[i] = MakeWorkingView(views[i], mesh, options.max_image_size);
        progress.Advance();
      },
      options.num_threads);
  const std::vector<std::vector<int>> neighbours =
      Neighbours(working, options.num_neighbors);
  const size_t num_faces = mesh.faces.size();
  const int num_threads =
      options.num_threads > 0 ? options.num_threads : DefaultNumThreads();
  std::vector<std::vector<double>> sums(num_threads, std::vector<double>(num_faces, 0.0));
  std::vector<std::vector<size_t>> counts(num_threads, std::vector<size_t>(num_faces, 0));
  ParallelForRanges(
      0, n,
      [&](int64_t begin, int64_t end, int thread) {
        for (int64_t i = begin; i < end; ++i) {
          AccumulateView(working, static_cast<int>(i), neighbours[i],
                         options.depth_tolerance, &sums[thread], &counts[thread]);
          progress.Advance();
        }
      },
      num_threads);
  progress.Finish();
  FaceDifferences out;
  out.mean_difference.assign(num_faces, 0.0);
  out.num_samples.assign(num_faces, 0);
  for (int t = 0; t < num_threads; ++t) {
    for (size_t f = 0; f < num_faces; ++f) {
      out.mean_difference[f] += sums[t][f];
      out.num_samples[f] += counts[t][f];
    }
  }
  for (size_t f = 0; f < num_faces; ++f) {
    if (out.num_samples[f] > 0) out.mean_difference[f] /= out.num_samples[f];
  }
  return out;
}

FaceConsistencyResult RemoveInconsistentFaces(
    const std::vector<FaceConsistencyView>& views, const TriangleMesh& mesh,
    const FaceConsistencyOptions& options) {
  options.Check();
  Timer timer;
  FaceConsistencyResult result;
  result.mesh = mesh;
  result.num_faces = mesh.faces.size();
  if (!options.enabled || views.size() < 2 || mesh.faces.empty()) return result;
  const FaceDifferences measured = MeasureFaceDifferences(views, mesh, options);
  std::vector<Eigen::Vector3i> kept;
  kept.reserve(mesh.faces.size());
  std::vector<double> judged;
  double judged_samples = 0, removed_samples = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const size_t samples = measured.num_samples[f];
    const bool judge = samples >= static_cast<size_t>(options.min_samples);
    if (judge) {
      judged.push_back(measured.mean_difference[f]);
      judged_samples += samples;
    }
    if (judge && measured.mean_difference[f] > options.max_colour_difference) {
      removed_samples += samples;
      continue;
    }
    kept.push_back(mesh.faces[f]);
  }
  result.num_judged = judged.size();
  result.num_removed = mesh.faces.size() - kept.size();
  result.removed_area_share = judged_samples > 0 ? removed_samples / judged_samples : 0.0;
  if (!judged.empty()) {
    std::nth_element(judged.begin(), judged.begin() + judged.size() / 2, judged.end());
    result.median_difference = judged[judged.size() / 2];
  }
  result.mesh.faces = std::move(kept);
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace fvs::mvs
