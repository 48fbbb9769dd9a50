#include "fvs/mvs/mesh_refinement.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fvs/geometry/rasterizer.h"
#include "fvs/mvs/mesh_subdivision.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace fvs::mvs {
namespace {

constexpr char kWho[] = "mesh refinement";
constexpr double kPi = 3.14159265358979323846;
constexpr double kMinPatchVariance = 1e-4;  // grey std 0.01: no texture, no data term

// One photo at one level: grey values, its camera and its depth of the current mesh.
struct LevelView {
  PinholeCamera camera;
  Image grey;
  Image depth;
  Eigen::Vector3d centre;
};

// Vertex neighbours as compressed rows.
struct Adjacency {
  std::vector<int> offsets;  // size num_vertices + 1
  std::vector<int> neighbours;
};

// What the search found for one vertex.
struct DataTerm {
  double displacement = 0;  // along the normal, world units
  double weight = 0;        // 0: no data
  double score = 0;
  double step = 0;  // half a reference pixel, world units (the search's unit)
};

Image ToGrey(const Image& photo) {
  if (photo.channels == 1) return photo;
  Image grey(photo.width, photo.height, 1);
  for (int y = 0; y < photo.height; ++y) {
    for (int x = 0; x < photo.width; ++x) {
      float sum = 0;
      for (int c = 0; c < photo.channels; ++c) sum += photo.at(x, y, c);
      grey.at(x, y) = sum / photo.channels;
    }
  }
  return grey;
}

// Bilinear grey value at COLMAP pixel coordinates (centres at +0.5); false outside.
bool SampleGrey(const Image& image, double u, double v, double* value) {
  const double x = u - 0.5;
  const double y = v - 0.5;
  if (!(x >= 0 && y >= 0 && x <= image.width - 1 && y <= image.height - 1)) return false;
  const int x0 = std::min(static_cast<int>(x), std::max(0, image.width - 2));
  const int y0 = std::min(static_cast<int>(y), std::max(0, image.height - 2));
  const int x1 = std::min(x0 + 1, image.width - 1);
  const int y1 = std::min(y0 + 1, image.height - 1);
  const double fx = x - x0;
  const double fy = y - y0;
  const double top = image.at(x0, y0) * (1 - fx) + image.at(x1, y0) * fx;
  const double bottom = image.at(x0, y1) * (1 - fx) + image.at(x1, y1) * fx;
  *value = top * (1 - fy) + bottom * fy;
  return true;
}

std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d& a = mesh.vertices[f[0]];
    const Eigen::Vector3d n = (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a);
    if (!n.allFinite()) continue;
    for (int k = 0; k < 3; ++k) normals[f[k]] += n;  // area weighted
  }
  for (Eigen::Vector3d& n : normals) {
    const double length = n.norm();
    n = length > 0 && std::isfinite(length) ? Eigen::Vector3d(n / length)
                                            : Eigen::Vector3d::Zero();
  }
  return normals;
}

Adjacency BuildAdjacency(const TriangleMesh& mesh) {
  std::vector<std::vector<int>> lists(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      lists[f[k]].push_back(f[(k + 1) % 3]);
      lists[f[k]].push_back(f[(k + 2) % 3]);
    }
  }
  Adjacency adjacency;
  adjacency.offsets.push_back(0);
  for (std::vector<int>& list : lists) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    adjacency.neighbours.insert(adjacency.neighbours.end(), list.begin(), list.end());
    adjacency.offsets.push_back(static_cast<int>(adjacency.neighbours.size()));
  }
  return adjacency;
}

// The photos of one level, grey and resized, with their depth of `mesh`.
std::vector<LevelView> MakeLevel(const std::vector<LevelView>& finest, int size) {
  std::vector<LevelView> level;
  for (const LevelView& f : finest) {
    LevelView v;
    const auto [w, h] = ScaledSize(f.grey.width, f.grey.height, size);
    v.grey = w == f.grey.width ? f.grey : ResizeArea(f.grey, w, h);
    v.camera = f.camera.Resized(w, h);
    v.centre = f.centre;
    level.push_back(std::move(v));
  }
  return level;
}

void RenderDepths(const TriangleMesh& mesh, int num_threads,
                  std::vector<LevelView>* views) {
  RasterizeOptions raster;
  raster.num_threads = num_threads;
  for (LevelView& v : *views) v.depth = Rasterize(mesh, v.camera, raster).depth;
}

// True when `view` sees `x` (normal `n`) unoccluded; *cos_angle is |n . ray|.
bool Sees(const LevelView& view, const Eigen::Vector3d& x, const Eigen::Vector3d& n,
          double min_cos, double* cos_angle, double* depth) {
  const Eigen::Vector3d xc = view.camera.WorldToCamera(x);
  if (!(xc.z() > 0)) return false;
  const Eigen::Vector2d p = view.camera.CameraToPixel(xc);
  const int px = static_cast<int>(std::floor(p.x()));
  const int py = static_cast<int>(std::floor(p.y()));
  if (px < 0 || py < 0 || px >= view.camera.width || py >= view.camera.height)
    return false;
  const Eigen::Vector3d ray = (view.centre - x).normalized();
  *cos_angle = std::abs(n.dot(ray));
  if (!(*cos_angle >= min_cos)) return false;
  const double z = view.depth.at(px, py);
  // The vertex is on the rendered surface up to the slope across a pixel.
  const double pixel = xc.z() / view.camera.fx;
  const double tolerance = 0.01 * xc.z() + 2 * pixel / std::max(*cos_angle, 0.2);
  if (!(z > 0) || std::abs(z - xc.z()) > tolerance) return false;
  *depth = xc.z();
  return true;
}

// NCC of two equally long sample vectors; 0 when `b` has no variance; NaN when `a` has
// none (no texture).
double Ncc(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t n = a.size();
  double ma = 0, mb = 0;
  for (size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  double saa = 0, sbb = 0, sab = 0;
  for (size_t i = 0; i < n; ++i) {
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
    sab += (a[i] - ma) * (b[i] - mb);
  }
  if (!(saa / n >= kMinPatchVariance)) return std::nan("");
  if (!(sbb / n > 1e-8)) return 0;
  return sab / std::sqrt(saa * sbb);
}

class VertexSearch {
 public:
  VertexSearch(const std::vector<LevelView>& views, const MeshRefinementOptions& o)
      : views_(views), o_(o) {
    min_cos_ = std::cos(o.max_view_angle * kPi / 180);
    max_cos_triangulation_ = std::cos(o.min_triangulation_angle * kPi / 180);
  }

  DataTerm Run(const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
    DataTerm term;
    if (n.isZero()) return term;
    if (!ChooseViews(x, n)) return term;
    const LevelView& ref = views_[reference_];
    term.step = 0.5 * reference_depth_ / ref.camera.fx;
    // Tangent basis of the patch, one reference pixel apart.
    const Eigen::Vector3d t1 = n.unitOrthogonal() * (2 * term.step);
    const Eigen::Vector3d t2 = n.cross(t1);
    const int m = o_.search_steps;
    std::vector<double> scores(2 * m + 1, std::nan(""));
    for (int k = -m; k <= m; ++k) {
      scores[k + m] = Score(x + n * (k * term.step), t1, t2);
      if (!std::isfinite(scores[k + m])) return term;  // textureless or left a photo
    }
    const int best =
        static_cast<int>(std::max_element(scores.begin(), scores.end()) - scores.begin());
    const double worst = *std::min_element(scores.begin(), scores.end());
    term.score = scores[best];
    if (term.score < o_.min_ncc || term.score - worst < o_.min_peak) return term;
    double offset = best - m;
    if (best > 0 && best < 2 * m) {
      const double a = scores[best - 1], b = scores[best], c = scores[best + 1];
      const double denom = a - 2 * b + c;
      if (denom < 0) offset += std::clamp(0.5 * (a - c) / denom, -0.5, 0.5);
    }
    term.displacement = offset * term.step;
    term.weight = term.score;
    return term;
  }

  // The score of the surface as it is (offset 0); NaN where Run would have no data.
  double ScoreAt(const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
    if (n.isZero() || !ChooseViews(x, n)) return std::nan("");
    const double step = 0.5 * reference_depth_ / views_[reference_].camera.fx;
    const Eigen::Vector3d t1 = n.unitOrthogonal() * (2 * step);
    return Score(x, t1, n.cross(t1));
  }

 private:
  // The reference (most frontal) and up to num_sources others that see x.
  bool ChooseViews(const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
    candidates_.clear();
    for (size_t i = 0; i < views_.size(); ++i) {
      double cos_angle = 0, depth = 0;
      if (Sees(views_[i], x, n, min_cos_, &cos_angle, &depth)) {
        candidates_.push_back({cos_angle, static_cast<int>(i), depth});
      }
    }
    if (candidates_.size() < 2) return false;
    std::sort(candidates_.begin(), candidates_.end(),
              [](const Candidate& a, const Candidate& b) { return a.cos > b.cos; });
    reference_ = candidates_[0].index;
    reference_depth_ = candidates_[0].depth;
    const Eigen::Vector3d ref_ray = (views_[reference_].centre - x).normalized();
    sources_.clear();
    for (size_t i = 1;
         i < candidates_.size() && static_cast<int>(sources_.size()) < o_.num_sources;
         ++i) {
      const Eigen::Vector3d ray = (views_[candidates_[i].index].centre - x).normalized();
      if (ray.dot(ref_ray) <= max_cos_triangulation_)
        sources_.push_back(candidates_[i].index);
    }
    return !sources_.empty();
  }

  // Mean NCC of the reference's patch at the plane through p with each source's; NaN
  // when the reference patch has no texture or leaves the reference photo.
  double Score(const Eigen::Vector3d& p, const Eigen::Vector3d& t1,
               const Eigen::Vector3d& t2) {
    if (!SamplePatch(views_[reference_], p, t1, t2, &reference_samples_)) {
      return std::nan("");
    }
    double sum = 0;
    int count = 0;
    for (int s : sources_) {
      if (!SamplePatch(views_[s], p, t1, t2, &source_samples_)) continue;
      const double ncc = Ncc(reference_samples_, source_samples_);
      if (std::isnan(ncc)) return ncc;
      sum += ncc;
      ++count;
    }
    return count > 0 ? sum / count : std::nan("");
  }

  bool SamplePatch(const LevelView& view, const Eigen::Vector3d& p,
                   const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                   std::vector<double>* samples) const {
    const int r = o_.patch_size / 2;
    samples->clear();
    for (int b = -r; b <= r; ++b) {
      for (int a = -r; a <= r; ++a) {
        const Eigen::Vector3d xc = view.camera.WorldToCamera(p + a * t1 + b * t2);
        if (!(xc.z() > 0)) return false;
        const Eigen::Vector2d uv = view.camera.CameraToPixel(xc);
        double value = 0;
        if (!SampleGrey(view.grey, uv.x(), uv.y(), &value)) return false;
        samples->push_back(value);
      }
    }
    return true;
  }

  struct Candidate {
    double cos;
    int index;
    double depth;
  };
  const std::vector<LevelView>& views_;
  const MeshRefinementOptions& o_;
  double min_cos_ = 0;
  double max_cos_triangulation_ = 1;
  std::vector<Candidate> candidates_;
  std::vector<int> sources_;
  int reference_ = 0;
  double reference_depth_ = 0;
  std::vector<double> reference_samples_;
  std::vector<double> source_samples_;
};

// The smoothness term: displacements along each vertex's normal, regularised.
std::vector<double> Regularise(const std::vector<DataTerm>& data,
                               const std::vector<Eigen::Vector3d>& normals,
                               const Adjacency& adjacency,
                               const MeshRefinementOptions& o) {
  const size_t n = data.size();
  std::vector<double> x(n, 0), next(n, 0);
  for (size_t v = 0; v < n; ++v) x[v] = data[v].weight > 0 ? data[v].displacement : 0;
  for (int it = 0; it < o.smoothing_iterations; ++it) {
    for (size_t v = 0; v < n; ++v) {
      double numerator = data[v].weight * data[v].displacement;
      double denominator = data[v].weight;
      for (int k = adjacency.offsets[v]; k < adjacency.offsets[v + 1]; ++k) {
        const int u = adjacency.neighbours[k];
        numerator += o.smoothness * normals[u].dot(normals[v]) * x[u];
        denominator += o.smoothness;
      }
      next[v] = denominator > 0 ? numerator / denominator : 0;
    }
    x.swap(next);
  }
  for (size_t v = 0; v < n; ++v) {
    // A vertex outside every photo's search has no step: it stays.
    const double range = o.search_steps * data[v].step;
    x[v] = std::isfinite(x[v]) ? std::clamp(x[v], -range, range) : 0;
  }
  return x;
}

// The step of a vertex without its own search: its neighbours' mean, so a smoothed
// displacement can move it.
void FillSteps(const Adjacency& adjacency, std::vector<DataTerm>* data) {
  for (size_t v = 0; v < data->size(); ++v) {
    if ((*data)[v].step > 0) continue;
    double sum = 0;
    int count = 0;
    for (int k = adjacency.offsets[v]; k < adjacency.offsets[v + 1]; ++k) {
      const double s = (*data)[adjacency.neighbours[k]].step;
      if (s > 0) {
        sum += s;
        ++count;
      }
    }
    if (count > 0) (*data)[v].step = sum / count;
  }
}

// Mean score at offset 0 over the vertices with texture seen by two photos: the
// photo-consistency of `mesh` as it stands, comparable between meshes at one level.
double MeanScore(const TriangleMesh& mesh, const MeshRefinementOptions& o,
                 std::vector<LevelView>* views) {
  RenderDepths(mesh, o.num_threads, views);
  const std::vector<Eigen::Vector3d> normals = VertexNormals(mesh);
  const int64_t n = static_cast<int64_t>(mesh.vertices.size());
  std::vector<double> scores(n, std::nan(""));
  ParallelForRanges(
      0, n,
      [&](int64_t begin, int64_t end, int) {
        VertexSearch search(*views, o);
        for (int64_t v = begin; v < end; ++v)
          scores[v] = search.ScoreAt(mesh.vertices[v], normals[v]);
      },
      o.num_threads);
  double sum = 0;
  int64_t count = 0;
  for (double s : scores) {
    if (std::isfinite(s)) {
      sum += s;
      ++count;
    }
  }
  return count > 0 ? sum / count : 0;
}

struct IterationStats {
  double data_share = 0;
};

IterationStats Iterate(const std::vector<LevelView>& views, const Adjacency& adjacency,
                       const MeshRefinementOptions& o, TriangleMesh* mesh,
                       std::vector<double>* moves_in_steps) {
  const std::vector<Eigen::Vector3d> normals = VertexNormals(*mesh);
  const int64_t n = static_cast<int64_t>(mesh->vertices.size());
  std::vector<DataTerm> data(n);
  ParallelForRanges(
      0, n,
      [&](int64_t begin, int64_t end, int) {
        VertexSearch search(views, o);
        for (int64_t v = begin; v < end; ++v)
          data[v] = search.Run(mesh->vertices[v], normals[v]);
      },
      o.num_threads);
  IterationStats stats;
  int with_data = 0;
  for (const DataTerm& d : data) with_data += d.weight > 0 ? 1 : 0;
  stats.data_share = n > 0 ? static_cast<double>(with_data) / n : 0;
  FillSteps(adjacency, &data);
  const std::vector<double> x = Regularise(data, normals, adjacency, o);
  moves_in_steps->clear();
  for (int64_t v = 0; v < n; ++v) {
    const Eigen::Vector3d moved = mesh->vertices[v] + normals[v] * x[v];
    if (!moved.allFinite() || x[v] == 0) continue;
    mesh->vertices[v] = moved;
    moves_in_steps->push_back(std::abs(x[v]) / data[v].step);
  }
  return stats;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t k = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

}  // namespace

void MeshRefinementOptions::Check() const {
  Require(max_image_size >= 16, kWho, "--Refine.max_image_size must be >= 16");
  Require(num_levels >= 1 && num_levels <= 6, kWho,
          "--Refine.num_levels must be in [1, 6]");
  Require(num_iterations >= 1, kWho, "--Refine.num_iterations must be >= 1");
  Require(patch_size >= 3 && patch_size % 2 == 1 && patch_size <= 15, kWho,
          "--Refine.patch_size must be odd and in [3, 15]");
  Require(search_steps >= 1 && search_steps <= 32, kWho,
          "--Refine.search_steps must be in [1, 32]");
  Require(num_sources >= 1, kWho, "--Refine.num_sources must be >= 1");
  Require(std::isfinite(min_ncc) && min_ncc >= -1 && min_ncc <= 1, kWho,
          "--Refine.min_ncc must be in [-1, 1]");
  Require(std::isfinite(min_peak) && min_peak >= 0, kWho,
          "--Refine.min_peak must be >= 0");
  Require(std::isfinite(max_view_angle) && max_view_angle > 0 && max_view_angle < 90,
          kWho, "--Refine.max_view_angle must be in (0, 90) degrees");
  Require(std::isfinite(min_triangulation_angle) && min_triangulation_angle >= 0 &&
              min_triangulation_angle < 90,
          kWho, "--Refine.min_triangulation_angle must be in [0, 90) degrees");
  Require(std::isfinite(smoothness) && smoothness >= 0, kWho,
          "--Refine.smoothness must be >= 0");
  Require(std::isfinite(max_edge_pixels) && max_edge_pixels >= 0, kWho,
          "--Refine.max_edge_pixels must be >= 0 (0: no subdivision)");
  Require(max_vertices >= 1, kWho, "--Refine.max_vertices must be >= 1");
  Require(smoothing_iterations >= 0, kWho, "--Refine.smoothing_iterations must be >= 0");
  Require(std::isfinite(max_seconds) && max_seconds > 0, kWho,
          "--Refine.max_seconds must be positive");
}

std::string MeshRefinementOptions::ToString() const {
  if (!enabled) return "refine=off";
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "refine size=%d levels=%d iterations=%d patch=%d steps=%d sources=%d "
                "ncc=%.17g peak=%.17g angle=%.17g tri=%.17g smooth=%.17g smooth_it=%d "
                "seconds=%.17g edge=%.17g max_vertices=%d",
                max_image_size, num_levels, num_iterations, patch_size, search_steps,
                num_sources, min_ncc, min_peak, max_view_angle, min_triangulation_angle,
                smoothness, smoothing_iterations, max_seconds, max_edge_pixels,
                max_vertices);
  return buffer;
}

std::string MeshRefinementResult::Summary() const {
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "mesh refinement: %d iterations%s; %zu vertices added; vertices with a "
                "data term %.1f%% -> "
                "%.1f%%; mean NCC of the surface %.3f -> %.3f; median move %.2f px",
                num_iterations_run,
                stopped_at_time_bound ? " (stopped at the time bound)" : "",
                num_vertices_added, 100 * first_data_share, 100 * last_data_share,
                ncc_before, ncc_after, median_move_pixels);
  return buffer;
}

MeshRefinementResult RefineMesh(const std::vector<MeshRefinementView>& views,
                                const TriangleMesh& mesh,
                                const MeshRefinementOptions& options) {
  options.Check();
  Timer timer;
  MeshRefinementResult result;
  result.mesh = mesh;
  if (views.size() < 2 || mesh.faces.empty()) return result;
  result.mesh.normals.clear();  // stale once the vertices move
  std::vector<LevelView> finest;
  for (const MeshRefinementView& v : views) {
    LevelView level;
    level.camera = v.camera;
    level.centre = v.camera.Center();
    const Image grey = ToGrey(v.photo);
    const auto [w, h] = ScaledSize(grey.width, grey.height, options.max_image_size);
    level.grey = w == grey.width && h == grey.height ? grey : ResizeArea(grey, w, h);
    level.camera = v.camera.Resized(w, h);
    finest.push_back(std::move(level));
  }
  Adjacency adjacency = BuildAdjacency(mesh);
  Progress progress("mesh refinement", options.num_levels * options.num_iterations + 2);
  result.ncc_before = MeanScore(mesh, options, &finest);
  progress.Advance();
  std::vector<double> moves;
  for (int level = 0; level < options.num_levels && !result.stopped_at_time_bound;
       ++level) {
    const int size =
        std::max(16, options.max_image_size >> (options.num_levels - 1 - level));
    std::vector<LevelView> views_at_level = MakeLevel(finest, size);
    // Moves are reported in finest-level pixels: a step is half a pixel at this level.
    const double pixels_per_step =
        0.5 * static_cast<double>(finest[0].grey.width) / views_at_level[0].grey.width;
    if (options.max_edge_pixels > 0 &&
        result.mesh.vertices.size() < static_cast<size_t>(options.max_vertices)) {
      std::vector<PinholeCamera> cameras;
      for (const LevelView& v : views_at_level) cameras.push_back(v.camera);
      const size_t before = result.mesh.vertices.size();
      if (SubdivideLongEdges(cameras, options.max_edge_pixels, &result.mesh) > 0) {
        adjacency = BuildAdjacency(result.mesh);
        result.num_vertices_added += result.mesh.vertices.size() - before;
      }
    }
    for (int it = 0; it < options.num_iterations; ++it) {
      RenderDepths(result.mesh, options.num_threads, &views_at_level);
      const IterationStats stats =
          Iterate(views_at_level, adjacency, options, &result.mesh, &moves);
      if (result.num_iterations_run == 0) result.first_data_share = stats.data_share;
      result.last_data_share = stats.data_share;
      result.median_move_pixels = Median(moves) * pixels_per_step;
      ++result.num_iterations_run;
      progress.Advance();
      if (timer.Seconds() > options.max_seconds) {
        result.stopped_at_time_bound = true;
        break;
      }
    }
  }
  result.ncc_after = MeanScore(result.mesh, options, &finest);
  progress.Finish();
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace fvs::mvs
