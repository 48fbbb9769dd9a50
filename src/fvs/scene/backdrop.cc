#include "fvs/scene/backdrop.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "fvs/geometry/rasterizer.h"
#include "fvs/geometry/warp.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace fvs {

namespace {

const char* kWho = "--Backdrop";

// A photo as the fit compares it: small, with the mesh's depth at the same size.
struct SmallView {
  PinholeCamera camera;
  Image photo;
  Image mesh_depth;
};

// Colours seen of one hypothesis: running sums for the mean squared deviation.
struct ColourSpread {
  double sum[3] = {0, 0, 0};
  double sum_sq = 0;
  int n = 0;
  void Add(const float* rgb) {
    for (int c = 0; c < 3; ++c) {
      sum[c] += rgb[c];
      sum_sq += static_cast<double>(rgb[c]) * rgb[c];
    }
    ++n;
  }
  // Mean over the channels of the squared deviation from the mean colour.
  double Cost() const {
    if (n == 0) return 0;
    double mean_sq = 0;
    for (double s : sum) mean_sq += (s / n) * (s / n);
    // Unbiased (n - 1): two photos that happen to agree are weaker evidence than ten.
    const double biased = std::max(0.0, (sum_sq / n - mean_sq) / 3.0);
    return n > 1 ? biased * n / (n - 1) : biased;
  }
};

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

Eigen::Vector3d MedianPoint(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d m;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> coord;
    coord.reserve(points.size());
    for (const auto& p : points) coord.push_back(p(axis));
    m(axis) = Percentile(std::move(coord), 0.5);
  }
  return m;
}

std::vector<SmallView> MakeSmallViews(const std::vector<BackdropView>& views,
                                      const TriangleMesh& mesh,
                                      const BackdropOptions& options) {
  std::vector<SmallView> small(views.size());
  Progress progress("backdrop: small views", static_cast<int64_t>(views.size()));
  ParallelFor(
      0, static_cast<int64_t>(views.size()),
      [&](int64_t i) {
        const BackdropView& v = views[i];
        Require(v.photo.channels == 3 && !v.photo.empty(), "backdrop",
                "a photo is empty or not RGB");
        const auto [w, h] =
            ScaledSize(v.camera.width, v.camera.height, options.max_image_size, 4);
        small[i].camera = v.camera.Resized(w, h);
        small[i].photo = ResizeArea(v.photo, w, h);
        RasterizeOptions raster;
        raster.num_threads = 1;
        small[i].mesh_depth = Rasterize(mesh, small[i].camera, raster).depth;
        progress.Advance();
      },
      options.num_threads);
  progress.Finish();
  return small;
}

// The mesh's depth at the nearest pixel to (u, v), which lies inside the image.
float NearestDepth(const Image& depth, double u, double v) {
  const int x = std::clamp(static_cast<int>(u), 0, depth.width - 1);
  const int y = std::clamp(static_cast<int>(v), 0, depth.height - 1);
  return depth.at(x, y);
}

bool Inside(const PinholeCamera& c, const Eigen::Vector2d& p) {
  return p.x() >= 0 && p.y() >= 0 && p.x() < c.width && p.y() < c.height;
}

// The colours the photos show of the finite point X (see the header's rules).
ColourSpread SpreadAt(const std::vector<SmallView>& views, const Eigen::Vector3d& x,
                      const Eigen::Vector3d& direction) {
  ColourSpread spread;
  float rgb[3];
  for (const SmallView& v : views) {
    // The inner side only: a camera beyond the surface sees its far side.
    if ((v.camera.Center() - x).dot(direction) >= 0) continue;
    const Eigen::Vector3d xc = v.camera.WorldToCamera(x);
    if (!(xc.z() > 0)) continue;
    const Eigen::Vector2d p = v.camera.CameraToPixel(xc);
    if (!Inside(v.camera, p)) continue;
    const float d = NearestDepth(v.mesh_depth, p.x(), p.y());
    if (d > 0 && d < 0.98 * xc.z()) continue;  // the mesh stands in front
    SampleBilinear(v.photo, p.x(), p.y(), rgb, true);
    spread.Add(rgb);
  }
  return spread;
}

// The colours the photos show looking along `direction`, at infinity (the warp's rule).
ColourSpread SpreadAtInfinity(const std::vector<SmallView>& views,
                              const Eigen::Vector3d& direction) {
  ColourSpread spread;
  float rgb[3];
  for (const SmallView& v : views) {
    const Eigen::Vector3d dc = v.camera.R * direction;
    if (!(dc.z() > 0)) continue;
    const Eigen::Vector2d p = v.camera.CameraToPixel(dc);
    if (!Inside(v.camera, p) || NearestDepth(v.mesh_depth, p.x(), p.y()) > 0) continue;
    SampleBilinear(v.photo, p.x(), p.y(), rgb, true);
    spread.Add(rgb);
  }
  return spread;
}

enum class Verdict { kFinite, kInfinity, kUnexplained, kUnseen };

struct DirectionFit {
  Verdict verdict = Verdict::kUnseen;
  double log_radius = 0;
};

// Colour variances closer than this count as a tie (a std of about 0.01).
constexpr double kTieCost = 1e-4;

// The median colour std of the radii seen by at least `required` photos.
double TypicalStd(const std::vector<ColourSpread>& spreads, int required) {
  std::vector<double> stds;
  for (const ColourSpread& s : spreads) {
    if (s.n >= required) stds.push_back(std::sqrt(s.Cost()));
  }
  return Percentile(std::move(stds), 0.5);
}

// A best std at most this share of the typical one is a distinct minimum (a surface).
constexpr double kDistinctMinimum = 0.5;

// Whether a direction's colours are explained by a finite radius: they agree at every
// radius (a textureless background: any radius will do, the most seen is kept), or the
// best radius is a distinct minimum within max_colour_std. A textured far background
// that no radius fits (a sky the photos see beyond the infinity cone of c) has a best
// std that is only the luck of the draw among radii, a little under the typical one.
bool Explained(double best_std, double typical_std, const BackdropOptions& options) {
  if (typical_std <= options.max_colour_std) return true;
  return best_std <= options.max_colour_std && best_std <= kDistinctMinimum * typical_std;
}

DirectionFit FitDirection(const std::vector<SmallView>& views, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d, const std::vector<double>& radii,
                          const BackdropOptions& options) {
  std::vector<ColourSpread> spreads;
  for (double r : radii) spreads.push_back(SpreadAt(views, c + r * d, d));
  const ColourSpread infinity = SpreadAtInfinity(views, d);
  // Hypotheses are compared only when about as many photos see them: a radius that two
  // or three neighbouring photos see agrees by that alone (a far sky "fits" any radius
  // seen by few), so each must be seen by half the photos of the best-seen hypothesis.
  int most_seen = infinity.n;
  for (const ColourSpread& s : spreads) most_seen = std::max(most_seen, s.n);
  const int required = std::max(options.min_views, (most_seen + 1) / 2);
  double best = -1;
  for (const ColourSpread& s : spreads) {
    if (s.n >= required && (best < 0 || s.Cost() < best)) best = s.Cost();
  }
  DirectionFit fit;
  const bool infinity_seen = infinity.n >= required;
  if (best < 0) {
    if (infinity_seen) fit.verdict = Verdict::kInfinity;
    return fit;  // else unseen
  }
  // Among the radii whose colours agree as well as the best, the one most photos see:
  // that is what lets the sources' occlusion test find it.
  int chosen = -1;
  for (size_t i = 0; i < radii.size(); ++i) {
    const ColourSpread& s = spreads[i];
    if (s.n < required || s.Cost() > best + kTieCost) continue;
    if (chosen < 0 || s.n > spreads[chosen].n) chosen = static_cast<int>(i);
  }
  const double finite_std = std::sqrt(best);
  if (infinity_seen &&
      std::sqrt(infinity.Cost()) + options.infinity_margin < finite_std) {
    fit.verdict = Verdict::kInfinity;
  } else if (!Explained(finite_std, TypicalStd(spreads, required), options)) {
    fit.verdict = Verdict::kUnexplained;
  } else {
    fit.verdict = Verdict::kFinite;
    fit.log_radius = std::log(radii[chosen]);
  }
  return fit;
}

std::vector<std::set<int>> Neighbours(const TriangleMesh& mesh) {
  std::vector<std::set<int>> n(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      n[f(k)].insert(f((k + 1) % 3));
      n[f(k)].insert(f((k + 2) % 3));
    }
  }
  return n;
}

// Median of each finite direction's log-radius and its finite neighbours'.
void SmoothRadii(const TriangleMesh& sphere, int iterations,
                 std::vector<DirectionFit>* fits) {
  const std::vector<std::set<int>> neighbours = Neighbours(sphere);
  for (int it = 0; it < iterations; ++it) {
    std::vector<DirectionFit> next = *fits;
    for (size_t i = 0; i < fits->size(); ++i) {
      if ((*fits)[i].verdict != Verdict::kFinite) continue;
      std::vector<double> values = {(*fits)[i].log_radius};
      for (int j : neighbours[i]) {
        if ((*fits)[j].verdict == Verdict::kFinite)
          values.push_back((*fits)[j].log_radius);
      }
      next[i].log_radius = Percentile(std::move(values), 0.5);
    }
    *fits = std::move(next);
  }
}

}  // namespace

void BackdropOptions::Check() const {
  Require(subdivisions >= 0 && subdivisions <= 7, kWho,
          "--Backdrop.subdivisions must be in [0, 7]");
  Require(max_image_size >= 16, kWho, "--Backdrop.max_image_size must be >= 16");
  Require(num_radii >= 2, kWho, "--Backdrop.num_radii must be >= 2");
  Require(std::isfinite(min_radius) && min_radius > 0, kWho,
          "--Backdrop.min_radius must be positive");
  Require(std::isfinite(max_radius) && max_radius > 0, kWho,
          "--Backdrop.max_radius must be positive");
  Require(min_views >= 2, kWho, "--Backdrop.min_views must be >= 2");
  Require(std::isfinite(infinity_margin) && infinity_margin >= 0, kWho,
          "--Backdrop.infinity_margin must be >= 0");
  Require(std::isfinite(max_colour_std) && max_colour_std > 0, kWho,
          "--Backdrop.max_colour_std must be positive");
  Require(smoothing_iterations >= 0, kWho,
          "--Backdrop.smoothing_iterations must be >= 0");
}

std::string BackdropOptions::ToString() const {
  if (!enabled) return "backdrop=off";
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "backdrop subdivisions=%d size=%d radii=%d min=%.17g max=%.17g views=%d "
                "margin=%.17g max_std=%.17g smoothing=%d",
                subdivisions, max_image_size, num_radii, min_radius, max_radius,
                min_views, infinity_margin, max_colour_std, smoothing_iterations);
  return buffer;
}

std::string BackdropFit::Summary() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "backdrop: %d of %d directions finite, %d at infinity (their colours "
                "agree better there), %d unexplained, %d unseen; %zu faces",
                num_finite, num_directions, num_infinity, num_unexplained, num_unseen,
                mesh.faces.size());
  return buffer;
}

TriangleMesh Icosphere(int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  for (const auto& v : std::vector<Eigen::Vector3d>{{-1, t, 0},
                                                    {1, t, 0},
                                                    {-1, -t, 0},
                                                    {1, -t, 0},
                                                    {0, -1, t},
                                                    {0, 1, t},
                                                    {0, -1, -t},
                                                    {0, 1, -t},
                                                    {t, 0, -1},
                                                    {t, 0, 1},
                                                    {-t, 0, -1},
                                                    {-t, 0, 1}}) {
    m.vertices.push_back(v.normalized());
  }
  m.faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoint;
    auto middle = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      const int index = static_cast<int>(m.vertices.size()) - 1;
      midpoint[key] = index;
      return index;
    };
    std::vector<Eigen::Vector3i> faces;
    for (const Eigen::Vector3i& f : m.faces) {
      const int a = middle(f(0), f(1)), b = middle(f(1), f(2)), c = middle(f(2), f(0));
      faces.insert(faces.end(), {{f(0), a, c}, {f(1), b, a}, {f(2), c, b}, {a, b, c}});
    }
    m.faces = std::move(faces);
  }
  return m;
}

BackdropFit FitBackdrop(const std::vector<BackdropView>& views, const TriangleMesh& mesh,
                        const BackdropOptions& options) {
  options.Check();
  BackdropFit fit;
  if (!options.enabled || mesh.vertices.empty() || mesh.faces.empty() ||
      static_cast<int>(views.size()) < options.min_views) {
    return fit;
  }
  fit.centre = MedianPoint(mesh.vertices);
  std::vector<double> distances;
  for (const auto& v : mesh.vertices) distances.push_back((v - fit.centre).norm());
  fit.mesh_radius = Percentile(distances, 0.9);
  double camera_distance = 0;
  for (const BackdropView& v : views) {
    camera_distance = std::max(camera_distance, (v.camera.Center() - fit.centre).norm());
  }
  const double r_min = options.min_radius * fit.mesh_radius;
  double r_max = options.max_radius * std::max(camera_distance, fit.mesh_radius);
  if (!(r_min > 0) || !std::isfinite(r_max)) return fit;  // a mesh of one point
  r_max = std::max(r_max, 2 * r_min);
  std::vector<double> radii;
  for (int i = 0; i < options.num_radii; ++i) {
    radii.push_back(r_min * std::pow(r_max / r_min, i / (options.num_radii - 1.0)));
  }

  const std::vector<SmallView> small = MakeSmallViews(views, mesh, options);
  const TriangleMesh sphere = Icosphere(options.subdivisions);
  fit.num_directions = static_cast<int>(sphere.vertices.size());
  std::vector<DirectionFit> fits(sphere.vertices.size());
  Progress progress("backdrop: directions", fit.num_directions);
  ParallelFor(
      0, fit.num_directions,
      [&](int64_t i) {
        fits[i] = FitDirection(small, fit.centre, sphere.vertices[i], radii, options);
        progress.Advance();
      },
      options.num_threads);
  progress.Finish();
  for (const DirectionFit& f : fits) {
    fit.num_finite += f.verdict == Verdict::kFinite;
    fit.num_infinity += f.verdict == Verdict::kInfinity;
    fit.num_unexplained += f.verdict == Verdict::kUnexplained;
    fit.num_unseen += f.verdict == Verdict::kUnseen;
  }
  SmoothRadii(sphere, options.smoothing_iterations, &fits);

  std::vector<int> index(fits.size(), -1);
  for (size_t i = 0; i < fits.size(); ++i) {
    if (fits[i].verdict != Verdict::kFinite) continue;
    index[i] = static_cast<int>(fit.mesh.vertices.size());
    fit.mesh.vertices.push_back(fit.centre +
                                std::exp(fits[i].log_radius) * sphere.vertices[i]);
  }
  for (const Eigen::Vector3i& f : sphere.faces) {
    if (index[f(0)] < 0 || index[f(1)] < 0 || index[f(2)] < 0) continue;
    // Reversed: counter-clockwise seen from the centre.
    fit.mesh.faces.emplace_back(index[f(0)], index[f(2)], index[f(1)]);
  }
  if (fit.mesh.faces.empty()) fit.mesh.vertices.clear();
  return fit;
}

Image RenderWithBackdrop(const TriangleMesh& mesh, const TriangleMesh& backdrop,
                         const PinholeCamera& camera, int num_threads) {
  RasterizeOptions options;
  options.num_threads = num_threads;
  Image depth = Rasterize(mesh, camera, options).depth;
  if (backdrop.faces.empty()) return depth;
  options.cull_back_faces = true;
  const Image behind = Rasterize(backdrop, camera, options).depth;
  for (size_t i = 0; i < depth.data.size(); ++i) {
    if (!(depth.data[i] > 0)) depth.data[i] = behind.data[i];
  }
  return depth;
}

}  // namespace fvs
