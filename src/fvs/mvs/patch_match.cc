#include "fvs/mvs/patch_match.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs::mvs {
namespace {

constexpr float kMaxCost = 2.0f;
constexpr int kMinCoarseSide = 64;
constexpr int kMaxWindowSamples = 41;  // per window row: radius <= 20
constexpr int kColourTableSize = 1024;
constexpr double kPi = 3.14159265358979323846;
// A plane seen nearly edge-on says nothing reliable (and its homography explodes).
constexpr double kMinCosIncidence = 0.1;

// Deterministic per-pixel random numbers (splitmix64): results do not depend on the
// thread count or on the order in which rows are processed.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return (Next() >> 11) * (1.0 / 9007199254740992.0); }
  double Normal() {
    const double u1 = std::max(Uniform(), 1e-300);
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }

 private:
  uint64_t state_;
};

uint64_t HashSeed(uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  Rng rng(a * 0x9E3779B97F4A7C15ULL ^ (b + 0x632BE59BD9B4E019ULL));
  Rng rng2(rng.Next() ^ (c * 0xD6E8FEB86659FD93ULL) ^ (d + 0xA0761D6478BD642FULL));
  return rng2.Next();
}

// Intrinsics in "index" coordinates: pixel (x, y) of the array sits at (x, y), i.e. the
// COLMAP principal point shifted by half a pixel.
struct IndexIntrinsics {
  double fx, fy, cx, cy;
  explicit IndexIntrinsics(const PinholeCamera& c)
      : fx(c.fx), fy(c.fy), cx(c.cx - 0.5), cy(c.cy - 0.5) {}
  Eigen::Vector3d Ray(double x, double y) const {
    return {(x - cx) / fx, (y - cy) / fy, 1.0};
  }
  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return k;
  }
};

struct Source {
  // Homography H = A + b m^T with m = K_ref^-T n / (n . X) (index coordinates).
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  // Reference camera frame -> source camera frame.
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  Eigen::Vector3d center;  // source centre in the reference camera frame
  IndexIntrinsics intrinsics{PinholeCamera{}};
  const float* grey = nullptr;
  int width = 0, height = 0;
  const Image* depth = nullptr;  // geometric pass only
};

class ViewSolver {
 public:
  ViewSolver(const std::vector<StereoView>& views, int ref,
             const std::vector<int>& sources, const PatchMatchOptions& options,
             const std::vector<const Image*>* source_depths)
      : options_(options), ref_(views[ref]), intr_(views[ref].camera) {
    width_ = ref_.camera.width;
    height_ = ref_.camera.height;
    const PinholeCamera& rc = ref_.camera;
    const Eigen::Matrix3d k_ref_inv = intr_.K().inverse();
    for (size_t i = 0; i < sources.size(); ++i) {
      const StereoView& sv = views[sources[i]];
      Source s;
      s.R = sv.camera.R * rc.R.transpose();
      s.t = sv.camera.t - s.R * rc.t;
      s.center = -s.R.transpose() * s.t;
      s.intrinsics = IndexIntrinsics(sv.camera);
      const Eigen::Matrix3d ks = s.intrinsics.K();
      s.A = ks * s.R * k_ref_inv;
      s.b = ks * s.t;
      s.grey = sv.grey.data.data();
      s.width = sv.grey.width;
      s.height = sv.grey.height;
      if (source_depths) s.depth = (*source_depths)[i];
      sources_.push_back(s);
    }
    geometric_ = source_depths != nullptr;
    top_k_ = std::min<int>(options.top_k, static_cast<int>(sources_.size()));
    PrecomputeReference();
    depth_.assign(static_cast<size_t>(width_) * height_, 0.0);
    normal_.assign(static_cast<size_t>(width_) * height_, Eigen::Vector3d::Zero());
    cost_.assign(static_cast<size_t>(width_) * height_, kMaxCost);
  }

  void Initialize(const DepthNormalMap* init) {
    ParallelFor(
        0, height_,
        [&](int64_t y) {
          for (int x = 0; x < width_; ++x) {
            const size_t i = Index(x, static_cast<int>(y));
            if (!window_scale_[i]) continue;
            double d = 0;
            Eigen::Vector3d n = Eigen::Vector3d::Zero();
            if (init && init->depth.data[i] > 0) {
              d = init->depth.data[i];
              n = Eigen::Vector3d(init->normal.data[3 * i], init->normal.data[3 * i + 1],
                                  init->normal.data[3 * i + 2]);
            }
            const Eigen::Vector3d ray = intr_.Ray(x, static_cast<int>(y));
            if (!(d >= ref_.depth_min && d <= ref_.depth_max) || !NormalUsable(n, ray)) {
              Rng rng(HashSeed(options_.seed, 0xA11CE, i, 0));
              d = RandomDepth(&rng);
              n = RandomNormal(&rng, ray);
            }
            depth_[i] = d;
            normal_[i] = n;
            cost_[i] = Cost(x, static_cast<int>(y), d, n, nullptr, nullptr);
          }
        },
        options_.num_threads);
  }

  // Perturbations shrink with the iteration number; a run that starts from converged
  // planes (finer level, geometric pass) starts at first_iteration.
  // `refining`: the planes came from a coarser level or the photometric pass, so (with
  // options.fast_refinement) the far neighbours and the random plane are skipped.
  void Iterate(int num_iterations, int first_iteration, bool refining) {
    const bool fast = refining && options_.fast_refinement;
    for (int iter = first_iteration; iter < first_iteration + num_iterations; ++iter) {
      for (int colour = 0; colour < 2; ++colour) {
        ParallelFor(
            0, height_,
            [&](int64_t y) { SweepRow(static_cast<int>(y), colour, iter, fast); },
            options_.num_threads);
      }
    }
  }

  DepthNormalMap Result() {
    DepthNormalMap out;
    out.depth = Image(width_, height_, 1);
    out.normal = Image(width_, height_, 3);
    out.cost = Image(width_, height_, 1, kMaxCost);
    ParallelFor(
        0, height_,
        [&](int64_t y64) {
          const int y = static_cast<int>(y64);
          std::vector<float> costs(sources_.size());
          std::vector<float> errors(sources_.size());
          for (int x = 0; x < width_; ++x) {
            const size_t i = Index(x, y);
            if (!window_scale_[i] || depth_[i] <= 0) continue;
            if (options_.filter && !PassesFilter(x, y, &costs, &errors)) continue;
            const Eigen::Vector3d& n = normal_[i];
            if (!std::isfinite(depth_[i]) || !n.allFinite()) continue;
            out.depth.data[i] = static_cast<float>(depth_[i]);
            for (int c = 0; c < 3; ++c)
              out.normal.data[3 * i + c] = static_cast<float>(n[c]);
            out.cost.data[i] = std::isfinite(cost_[i]) ? cost_[i] : kMaxCost;
          }
        },
        options_.num_threads);
    return out;
  }

 private:
  size_t Index(int x, int y) const { return static_cast<size_t>(y) * width_ + x; }

  // Mean and standard deviation of the reference window of every pixel (they do not
  // depend on the plane), and the textured mask.
  void PrecomputeReference() {
    const int r = options_.window_radius;
    pad_ = r * options_.max_window_scale;  // the widest window
    padded_width_ = width_ + 2 * pad_;
    const int padded_height = height_ + 2 * pad_;
    padded_ref_.resize(static_cast<size_t>(padded_width_) * padded_height);
    for (int y = 0; y < padded_height; ++y) {
      const int sy = std::clamp(y - pad_, 0, height_ - 1);
      for (int x = 0; x < padded_width_; ++x) {
        const int sx = std::clamp(x - pad_, 0, width_ - 1);
        padded_ref_[static_cast<size_t>(y) * padded_width_ + x] =
            ref_.grey.data[static_cast<size_t>(sy) * width_ + sx];
      }
    }
    for (int d = -r; d <= r; d += options_.window_step) offsets_.push_back(d);
    // Bilateral weights (as COLMAP): spatial Gaussian per window sample, times a colour
    // Gaussian of the grey difference to the centre pixel, from a table.
    const double sigma_spatial =
        options_.sigma_spatial > 0 ? options_.sigma_spatial : options_.window_radius;
    for (int dy : offsets_) {
      for (int dx : offsets_) {
        spatial_weight_.push_back(
            options_.sigma_color > 0
                ? static_cast<float>(std::exp(-(dx * dx + dy * dy) /
                                              (2 * sigma_spatial * sigma_spatial)))
                : 1.0f);
      }
    }
    colour_weight_.resize(kColourTableSize + 1);
    for (int q = 0; q <= kColourTableSize; ++q) {
      const double diff = static_cast<double>(q) / kColourTableSize;
      colour_weight_[q] =
          options_.sigma_color > 0
              ? static_cast<float>(std::exp(
                    -diff * diff / (2 * options_.sigma_color * options_.sigma_color)))
              : 1.0f;
    }
    ref_mean_.assign(static_cast<size_t>(width_) * height_, 0.f);
    ref_std_.assign(static_cast<size_t>(width_) * height_, 0.f);
    ref_weight_sum_.assign(static_cast<size_t>(width_) * height_, 0.f);
    window_scale_.assign(static_cast<size_t>(width_) * height_, 0);
    ParallelFor(
        0, height_,
        [&](int64_t y64) {
          const int y = static_cast<int>(y64);
          for (int x = 0; x < width_; ++x) {
            const size_t i = Index(x, y);
            window_scale_[i] = static_cast<uint8_t>(TexturedScale(x, y));
            // NCC uses the bilateral moments of the window it scores.
            const Moments m =
                WindowMoments(x, y, std::max<int>(window_scale_[i], 1), true);
            ref_mean_[i] = static_cast<float>(m.mean);
            ref_std_[i] = static_cast<float>(m.std);
            ref_weight_sum_[i] = static_cast<float>(m.weight_sum);
          }
        },
        options_.num_threads);
  }

  // The smallest window scale (1, 2, 4, ... max_window_scale) at which the grey std of
  // pixel (x, y)'s window reaches min_texture_std; 0 when none does. Scale 1 tests the
  // plain std (as before widening existed). A widened window tests the bilateral std,
  // what its NCC sees: a dark gap beside a bright column, or sky beside a roof, takes
  // the other side's texture at a tiny weight, so it does not count as textured there
  // and the foreground is not fattened across it.
  int TexturedScale(int x, int y) const {
    for (int scale = 1; scale <= options_.max_window_scale; scale *= 2) {
      if (WindowMoments(x, y, scale, scale > 1).std >= options_.min_texture_std) {
        return scale;
      }
    }
    return 0;
  }

  struct Moments {
    double mean, std, weight_sum;
  };

  // Grey mean and std of pixel (x, y)'s window at a scale, with the bilateral weights
  // or with unit weights.
  Moments WindowMoments(int x, int y, int scale, bool bilateral) const {
    float weights[kMaxWindowSamples * kMaxWindowSamples];
    if (bilateral) WindowWeights(x, y, scale, weights);
    double sum = 0, sum_sq = 0, weight_sum = 0;
    int k = 0;
    for (int dy : offsets_) {
      const float* row = RefRow(y + dy * scale);
      for (int dx : offsets_) {
        const double v = row[x + dx * scale];
        const double w = bilateral ? weights[k] : 1.0;
        sum += w * v;
        sum_sq += w * v * v;
        weight_sum += w;
        ++k;
      }
    }
    const double mean = sum / weight_sum;
    const double var = std::max(0.0, sum_sq / weight_sum - mean * mean);
    return {mean, std::sqrt(var), weight_sum};
  }

  // Bilateral weight of every window sample of pixel (x, y) at a window scale, row by
  // row. The spatial weights are in units of the window's own offsets, so a widened
  // window weighs its samples as the plain one does.
  void WindowWeights(int x, int y, int scale, float* weights) const {
    const float centre = RefRow(y)[x];
    int k = 0;
    for (int dy : offsets_) {
      const float* row = RefRow(y + dy * scale);
      for (int dx : offsets_) {
        const float diff = std::min(std::abs(row[x + dx * scale] - centre), 1.0f);
        weights[k] = spatial_weight_[k] *
                     colour_weight_[static_cast<int>(diff * kColourTableSize + 0.5f)];
        ++k;
      }
    }
  }

  const float* RefRow(int y) const {
    return padded_ref_.data() + static_cast<size_t>(y + pad_) * padded_width_ + pad_;
  }

  double RandomDepth(Rng* rng) const {
    // Uniform in inverse depth: equal steps in disparity, as a wide range needs.
    const double inv_min = 1.0 / ref_.depth_max, inv_max = 1.0 / ref_.depth_min;
    return 1.0 / (inv_min + rng->Uniform() * (inv_max - inv_min));
  }

  static bool NormalUsable(const Eigen::Vector3d& n, const Eigen::Vector3d& ray) {
    if (!n.allFinite() || std::abs(n.squaredNorm() - 1.0) > 1e-3) return false;
    return -n.dot(ray) / ray.norm() >= kMinCosIncidence;
  }

  Eigen::Vector3d RandomNormal(Rng* rng, const Eigen::Vector3d& ray) const {
    for (int attempt = 0; attempt < 16; ++attempt) {
      Eigen::Vector3d n(rng->Normal(), rng->Normal(), rng->Normal());
      if (n.norm() < 1e-6) continue;
      n.normalize();
      if (n.dot(ray) > 0) n = -n;
      if (NormalUsable(n, ray)) return n;
    }
    return -ray.normalized();
  }

  // The reference side of the weighted NCC of one pixel: the same for every source and
  // every candidate plane, so built once per pixel visit.
  struct Window {
    int scale;  // the pixel's window scale (window_scale_, at least 1)
    float ref_mean, ref_std, inv_weight_sum;
    float weights[kMaxWindowSamples * kMaxWindowSamples];
    float weighted_ref[kMaxWindowSamples * kMaxWindowSamples];
  };

  void MakeWindow(int x, int y, Window* window) const {
    const size_t i = Index(x, y);
    window->ref_mean = ref_mean_[i];
    window->ref_std = ref_std_[i];
    window->inv_weight_sum = 1.0f / ref_weight_sum_[i];
    window->scale = std::max<int>(window_scale_[i], 1);
    const int scale = window->scale;
    WindowWeights(x, y, scale, window->weights);
    int k = 0;
    for (int dy : offsets_) {
      const float* row = RefRow(y + dy * scale);
      for (int dx : offsets_) {
        window->weighted_ref[k] = window->weights[k] * row[x + dx * scale];
        ++k;
      }
    }
  }

  float Cost(int x, int y, double depth, const Eigen::Vector3d& n, float* photo_costs,
             float* geo_errors) const {
    Window window;
    MakeWindow(x, y, &window);
    return Cost(x, y, window, depth, n, photo_costs, geo_errors);
  }

  // Photometric cost 1 - NCC of the plane in every source, and (geometric pass) the
  // forward-backward reprojection error. Returns the aggregated cost.
  float Cost(int x, int y, const Window& window, double depth, const Eigen::Vector3d& n,
             float* photo_costs, float* geo_errors) const {
    const Eigen::Vector3d ray = intr_.Ray(x, y);
    const Eigen::Vector3d X = depth * ray;
    const double plane_d = n.dot(X);
    if (!(plane_d < 0)) return kMaxCost;
    // K_ref^-T n / (n . X)
    const Eigen::Vector3d m = Eigen::Vector3d(n.x() / intr_.fx, n.y() / intr_.fy,
                                              n.z() - n.x() * intr_.cx / intr_.fx -
                                                  n.y() * intr_.cy / intr_.fy) /
                              plane_d;
    float costs[64];
    const int num_sources = static_cast<int>(sources_.size());
    for (int s = 0; s < num_sources; ++s) {
      const Source& src = sources_[s];
      const Eigen::Matrix3d H = src.A + src.b * m.transpose();
      const size_t per_row = offsets_.size();
      float c = per_row == 4   ? WindowCost<4>(H, x, y, src, window)
                : per_row == 7 ? WindowCost<7>(H, x, y, src, window)
                               : WindowCost<0>(H, x, y, src, window);
      if (photo_costs) photo_costs[s] = c;
      if (geometric_) {
        const double err = ReprojectionError(X, x, y, src);
        if (geo_errors) geo_errors[s] = static_cast<float>(err);
        c += static_cast<float>(options_.geom_consistency_regularizer *
                                std::min(err, options_.geom_consistency_max_cost));
      }
      costs[s] = c;
    }
    // Mean of the best top_k: occluded or out-of-view sources have high costs and drop
    // out.
    std::partial_sort(costs, costs + top_k_, costs + num_sources);
    float sum = 0;
    for (int k = 0; k < top_k_; ++k) sum += costs[k];
    return sum / top_k_;
  }

  // kN > 0: the window has kN samples per row (the defaults, radius 3 with step 2 or 1),
  // known to the compiler so that it unrolls and vectorises the row loops.
  template <int kN>
  float WindowCost(const Eigen::Matrix3d& Hd, int x, int y, const Source& src,
                   const Window& window) const {
    // The centre must land inside the source image, in front of it.
    const Eigen::Vector3d hc = Hd * Eigen::Vector3d(x, y, 1.0);
    if (!(hc.z() > 1e-12)) return kMaxCost;
    const double cu = hc.x() / hc.z(), cv = hc.y() / hc.z();
    if (!(cu >= 0 && cv >= 0 && cu <= src.width - 1 && cv <= src.height - 1)) {
      return kMaxCost;
    }
    const Eigen::Matrix3f H = Hd.cast<float>();
    // The homography's denominator is affine in (x, y): positive at the four window
    // corners means positive everywhere in between, so the inner loop needs no test.
    const float r = static_cast<float>(offsets_.back() * window.scale);
    const float first = static_cast<float>(offsets_.front() * window.scale);
    for (float cy : {first, r}) {
      for (float cx : {first, r}) {
        if (!(H(2, 0) * (x + cx) + H(2, 1) * (y + cy) + H(2, 2) > 1e-6f)) return kMaxCost;
      }
    }
    const float step = static_cast<float>(options_.window_step * window.scale);
    const float max_u = static_cast<float>(std::max(src.width - 2, 0)) + 0.999f;
    const float max_v = static_cast<float>(std::max(src.height - 2, 0)) + 0.999f;
    const int w = src.width;
    const float* img = src.grey;
    const int n = kN > 0 ? kN : static_cast<int>(offsets_.size());
    float us[kMaxWindowSamples], vs[kMaxWindowSamples], samples[kMaxWindowSamples];
    float sum_s = 0, sum_ss = 0, sum_rs = 0;
    const float* weights = window.weights;
    const float* weighted_ref = window.weighted_ref;
    for (int row = 0; row < n; ++row) {
      const int dy = offsets_[row] * window.scale;
      const float sx = static_cast<float>(x) + first, sy = static_cast<float>(y + dy);
      const float hx = H(0, 0) * sx + H(0, 1) * sy + H(0, 2);
      const float hy = H(1, 0) * sx + H(1, 1) * sy + H(1, 2);
      const float hz = H(2, 0) * sx + H(2, 1) * sy + H(2, 2);
      // Vectorisable: the sample positions of one window row.
      for (int k = 0; k < n; ++k) {
        const float kk = static_cast<float>(k) * step;
        const float inv = 1.0f / (hz + kk * H(2, 0));
        us[k] = std::min(std::max((hx + kk * H(0, 0)) * inv, 0.0f), max_u);
        vs[k] = std::min(std::max((hy + kk * H(1, 0)) * inv, 0.0f), max_v);
      }
      for (int k = 0; k < n; ++k) {
        const int u0 = static_cast<int>(us[k]), v0 = static_cast<int>(vs[k]);
        const float au = us[k] - u0, av = vs[k] - v0;
        const float* p = img + static_cast<size_t>(v0) * w + u0;
        const float top = p[0] + au * (p[1] - p[0]);
        const float bottom = p[w] + au * (p[w + 1] - p[w]);
        samples[k] = top + av * (bottom - top);
      }
      // Two accumulators each: float additions are not reordered by the compiler, and one
      // long dependency chain would bound the loop by the adder's latency.
      float s0 = 0, s1 = 0, ss0 = 0, ss1 = 0, rs0 = 0, rs1 = 0;
      int k = 0;
      for (; k + 1 < n; k += 2) {
        const float a = samples[k], b = samples[k + 1];
        const float wa = weights[k] * a, wb = weights[k + 1] * b;
        s0 += wa;
        s1 += wb;
        ss0 += wa * a;
        ss1 += wb * b;
        rs0 += weighted_ref[k] * a;
        rs1 += weighted_ref[k + 1] * b;
      }
      if (k < n) {
        const float a = samples[k];
        const float wa = weights[k] * a;
        s0 += wa;
        ss0 += wa * a;
        rs0 += weighted_ref[k] * a;
      }
      sum_s += s0 + s1;
      sum_ss += ss0 + ss1;
      sum_rs += rs0 + rs1;
      weights += n;
      weighted_ref += n;
    }
    const float inv_w = window.inv_weight_sum;
    const float mean_s = sum_s * inv_w;
    const float var_s = sum_ss * inv_w - mean_s * mean_s;
    if (!(var_s > 1e-8f)) return kMaxCost;
    const float ncc =
        (sum_rs * inv_w - window.ref_mean * mean_s) / (window.ref_std * std::sqrt(var_s));
    return std::clamp(1.0f - ncc, 0.0f, kMaxCost);
  }

  // Forward-backward reprojection error (pixels) of the reference point X through the
  // source's depth map (Schönberger et al. 2016, Eq. 9); geom_consistency_max_cost when
  // the source has no depth there.
  double ReprojectionError(const Eigen::Vector3d& X, int x, int y,
                           const Source& src) const {
    const double max_err = options_.geom_consistency_max_cost;
    const Eigen::Vector3d xs = src.R * X + src.t;
    if (!(xs.z() > 0)) return max_err;
    const double us = src.intrinsics.fx * xs.x() / xs.z() + src.intrinsics.cx;
    const double vs = src.intrinsics.fy * xs.y() / xs.z() + src.intrinsics.cy;
    const Image& dm = *src.depth;
    // Nearest pixel; written so that NaN fails too (and no lround of a huge value).
    if (!(us > -0.5 && vs > -0.5 && us < dm.width - 0.5 && vs < dm.height - 0.5)) {
      return max_err;
    }
    const int iu = static_cast<int>(us + 0.5), iv = static_cast<int>(vs + 0.5);
    const double ds = dm.data[static_cast<size_t>(iv) * dm.width + iu];
    if (!(ds > 0)) return max_err;
    const Eigen::Vector3d back_src = ds * src.intrinsics.Ray(us, vs);
    const Eigen::Vector3d back_ref = src.R.transpose() * (back_src - src.t);
    if (!(back_ref.z() > 0)) return max_err;
    const double ur = intr_.fx * back_ref.x() / back_ref.z() + intr_.cx;
    const double vr = intr_.fy * back_ref.y() / back_ref.z() + intr_.cy;
    // Pixel-sized values: no overflow for hypot to guard against, at a fraction of its
    // cost.
    const double err = std::sqrt((ur - x) * (ur - x) + (vr - y) * (vr - y));
    return std::isfinite(err) ? err : max_err;
  }

  bool PassesFilter(int x, int y, std::vector<float>* costs,
                    std::vector<float>* errors) const {
    const size_t i = Index(x, y);
    const Eigen::Vector3d X = depth_[i] * intr_.Ray(x, y);
    Cost(x, y, depth_[i], normal_[i], costs->data(), errors->data());
    const double min_angle = options_.filter_min_triangulation_angle * kPi / 180.0;
    int consistent = 0;
    for (size_t s = 0; s < sources_.size(); ++s) {
      if (1.0 - (*costs)[s] < options_.filter_min_ncc) continue;
      if (geometric_ && (*errors)[s] > options_.filter_geom_consistency_max_cost)
        continue;
      const Eigen::Vector3d to_src = X - sources_[s].center;
      const double cos_angle = X.dot(to_src) / (X.norm() * to_src.norm());
      if (std::acos(std::clamp(cos_angle, -1.0, 1.0)) < min_angle) continue;
      ++consistent;
    }
    return consistent >= options_.filter_min_num_consistent;
  }

  // One checkerboard colour of one row: propagate the planes of the (other-coloured)
  // neighbours, then try random perturbations of the best plane.
  void SweepRow(int y, int colour, int iter, bool fast) {
    static const int kNeighbours[8][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1},
                                          {-3, 0}, {3, 0}, {0, -3}, {0, 3}};
    const double depth_sigma = options_.depth_perturbation * std::pow(0.5, iter);
    const double normal_sigma = options_.normal_perturbation * std::pow(0.5, iter);
    for (int x = (y + colour) % 2; x < width_; x += 2) {
      const size_t i = Index(x, y);
      if (!window_scale_[i]) continue;
      const Eigen::Vector3d ray = intr_.Ray(x, y);
      Window window;
      MakeWindow(x, y, &window);
      double best_d = depth_[i];
      Eigen::Vector3d best_n = normal_[i];
      float best_c = cost_[i];
      // Converged neighbours often share one plane: score each distinct plane once.
      double tried_d[16];
      Eigen::Vector3d tried_n[16];
      int num_tried = 0;
      auto already_tried = [&](double d, const Eigen::Vector3d& n) {
        if (std::abs(d - best_d) <= 1e-9 * best_d && (n - best_n).squaredNorm() < 1e-12) {
          return true;
        }
        for (int k = 0; k < num_tried; ++k) {
          if (std::abs(d - tried_d[k]) <= 1e-9 * d &&
              (n - tried_n[k]).squaredNorm() < 1e-12) {
            return true;
          }
        }
        return false;
      };
      auto consider = [&](double d, const Eigen::Vector3d& n) {
        if (!(d >= ref_.depth_min && d <= ref_.depth_max)) return;
        if (already_tried(d, n) || !NormalUsable(n, ray)) return;
        if (num_tried < 16) {
          tried_d[num_tried] = d;
          tried_n[num_tried++] = n;
        }
        const float c = Cost(x, y, window, d, n, nullptr, nullptr);
        if (c < best_c) {
          best_c = c;
          best_d = d;
          best_n = n;
        }
      };
      for (int k = 0; k < (fast ? 4 : 8); ++k) {
        const int nx = x + kNeighbours[k][0], ny = y + kNeighbours[k][1];
        if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) continue;
        const size_t j = Index(nx, ny);
        if (depth_[j] <= 0) continue;
        const Eigen::Vector3d& n = normal_[j];
        // Depth where this pixel's ray meets the neighbour's plane.
        const double denom = n.dot(ray);
        if (!(denom < 0)) continue;
        const double d = n.dot(depth_[j] * intr_.Ray(nx, ny)) / denom;
        consider(d, n);
      }
      Rng rng(HashSeed(options_.seed, i, iter, colour + 2));
      if (!fast) {
        const Eigen::Vector3d random_n = RandomNormal(&rng, ray);
        consider(RandomDepth(&rng), random_n);
      }
      const double perturbed_d =
          best_d * (1.0 + depth_sigma * (2.0 * rng.Uniform() - 1.0));
      Eigen::Vector3d perturbed_n =
          (best_n +
           normal_sigma * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal()))
              .normalized();
      if (perturbed_n.dot(ray) > 0) perturbed_n = -perturbed_n;
      const Eigen::Vector3d current_n = best_n;
      const double current_d = best_d;
      consider(perturbed_d, current_n);
      consider(current_d, perturbed_n);
      consider(perturbed_d, perturbed_n);
      depth_[i] = best_d;
      normal_[i] = best_n;
      cost_[i] = best_c;
    }
  }

  const PatchMatchOptions& options_;
  const StereoView& ref_;
  IndexIntrinsics intr_;
  int width_ = 0, height_ = 0;
  std::vector<Source> sources_;
  bool geometric_ = false;
  int top_k_ = 1;
  int pad_ = 0, padded_width_ = 0;
  std::vector<float> padded_ref_;
  std::vector<int> offsets_;
  std::vector<float> ref_mean_, ref_std_, ref_weight_sum_;
  std::vector<float> spatial_weight_;  // per window sample, row by row
  std::vector<float> colour_weight_;   // by |grey difference| * kColourTableSize
  // Per pixel: the factor its window's offsets are spread by, 0 = textureless at every
  // scale (no depth).
  std::vector<uint8_t> window_scale_;
  std::vector<double> depth_;
  std::vector<Eigen::Vector3d> normal_;
  std::vector<float> cost_;
};

// Area weights of source cells [j, j+1) covering destination cell i, for downscaling.
void ResampleLine(const float* src, int src_size, int src_stride, float* dst,
                  int dst_size, int dst_stride) {
  const double scale = static_cast<double>(src_size) / dst_size;
  for (int i = 0; i < dst_size; ++i) {
    const double a = i * scale, b = std::min<double>((i + 1) * scale, src_size);
    double sum = 0, weight = 0;
    for (int j = static_cast<int>(a); j < src_size && j < b; ++j) {
      const double w = std::min<double>(j + 1, b) - std::max<double>(j, a);
      if (w <= 0) continue;
      sum += w * src[static_cast<size_t>(j) * src_stride];
      weight += w;
    }
    dst[static_cast<size_t>(i) * dst_stride] =
        weight > 0 ? static_cast<float>(sum / weight) : 0.f;
  }
}

void CheckView(const StereoView& view, const std::string& role) {
  const std::string subject = view.name.empty() ? role : view.name;
  Require(view.camera.IsValid(), subject, "invalid camera");
  Require(view.grey.channels == 1 && view.grey.width == view.camera.width &&
              view.grey.height == view.camera.height,
          subject, "grey image does not match the camera size");
  Require(view.grey.width >= 2 && view.grey.height >= 2, subject, "image too small");
}

}  // namespace

Image DownscaleGrey(const Image& grey, int width, int height) {
  Require(grey.channels == 1 && width > 0 && height > 0 && width <= grey.width &&
              height <= grey.height,
          "DownscaleGrey", "bad sizes");
  Image rows(width, grey.height, 1);
  for (int y = 0; y < grey.height; ++y) {
    ResampleLine(grey.row(y), grey.width, 1, rows.row(y), width, 1);
  }
  Image out(width, height, 1);
  for (int x = 0; x < width; ++x) {
    ResampleLine(rows.data.data() + x, grey.height, width, out.data.data() + x, height,
                 width);
  }
  return out;
}

bool IsValidWindowScale(int scale) {
  return scale >= 1 && scale <= 16 && (scale & (scale - 1)) == 0;
}

void PatchMatchOptions::Check() const {
  const std::string s = "PatchMatchStereo";
  Require(window_radius >= 1 && window_radius <= 20, s,
          "window_radius must be in [1, 20]");
  Require(window_step >= 1 && window_step <= window_radius, s,
          "window_step must be in [1, window_radius]");
  Require(num_iterations >= 1, s, "num_iterations must be >= 1");
  Require(num_geometric_iterations >= 0, s, "num_geometric_iterations must be >= 0");
  Require(num_coarse_levels >= 0 && num_coarse_levels <= 4, s,
          "num_coarse_levels must be in [0, 4]");
  Require(num_fine_iterations >= 1, s, "num_fine_iterations must be >= 1");
  Require(top_k >= 1, s, "top_k must be >= 1");
  Require(std::isfinite(sigma_color) && std::isfinite(sigma_spatial), s,
          "sigma_color and sigma_spatial must be finite");
  Require(min_texture_std >= 0 && std::isfinite(min_texture_std), s,
          "min_texture_std must be >= 0");
  Require(IsValidWindowScale(max_window_scale), s,
          "max_window_scale must be 1, 2, 4, 8 or 16");
  Require(depth_perturbation > 0 && depth_perturbation < 1, s,
          "depth_perturbation must be in (0, 1)");
  Require(normal_perturbation > 0 && std::isfinite(normal_perturbation), s,
          "normal_perturbation must be > 0");
  Require(
      geom_consistency_regularizer >= 0 && std::isfinite(geom_consistency_regularizer), s,
      "geom_consistency_regularizer must be >= 0");
  Require(geom_consistency_max_cost > 0 && std::isfinite(geom_consistency_max_cost), s,
          "geom_consistency_max_cost must be > 0");
  Require(filter_min_ncc >= -1 && filter_min_ncc <= 1, s,
          "filter_min_ncc must be in [-1, 1]");
  Require(filter_min_triangulation_angle >= 0 && filter_min_triangulation_angle < 90, s,
          "filter_min_triangulation_angle must be in [0, 90)");
  Require(filter_geom_consistency_max_cost > 0, s,
          "filter_geom_consistency_max_cost must be > 0");
  Require(filter_min_num_consistent >= 0, s, "filter_min_num_consistent must be >= 0");
}

namespace {

// Half resolution of the reference and its sources, solved (recursively coarse-to-fine),
// then each plane carried to the full-resolution pixels it covers: the same plane, so the
// depth is re-intersected with the finer pixel's ray rather than copied.
DepthNormalMap SolveCoarse(const std::vector<StereoView>& views, int ref,
                           const std::vector<int>& sources,
                           const PatchMatchOptions& options) {
  auto half = [](const StereoView& v) {
    StereoView h = v;
    const int w = std::max(2, v.camera.width / 2), hh = std::max(2, v.camera.height / 2);
    h.camera = v.camera.Resized(w, hh);
    h.grey = DownscaleGrey(v.grey, w, hh);
    return h;
  };
  std::vector<StereoView> coarse_views;
  coarse_views.push_back(half(views[ref]));
  std::vector<int> coarse_sources;
  for (int s : sources) {
    coarse_sources.push_back(static_cast<int>(coarse_views.size()));
    coarse_views.push_back(half(views[s]));
  }
  PatchMatchOptions coarse_options = options;
  coarse_options.num_coarse_levels = options.num_coarse_levels - 1;
  coarse_options.filter = false;
  const DepthNormalMap coarse =
      PatchMatchView(coarse_views, 0, coarse_sources, coarse_options);
  const PinholeCamera& fine_cam = views[ref].camera;
  const PinholeCamera& coarse_cam = coarse_views[0].camera;
  DepthNormalMap fine;
  fine.depth = Image(fine_cam.width, fine_cam.height, 1);
  fine.normal = Image(fine_cam.width, fine_cam.height, 3);
  const double sx = static_cast<double>(coarse_cam.width) / fine_cam.width;
  const double sy = static_cast<double>(coarse_cam.height) / fine_cam.height;
  for (int y = 0; y < fine_cam.height; ++y) {
    const int cy = std::min(coarse_cam.height - 1, static_cast<int>((y + 0.5) * sy));
    for (int x = 0; x < fine_cam.width; ++x) {
      const int cx = std::min(coarse_cam.width - 1, static_cast<int>((x + 0.5) * sx));
      const double d = coarse.depth.at(cx, cy);
      if (!(d > 0)) continue;
      const Eigen::Vector3d n(coarse.normal.at(cx, cy, 0), coarse.normal.at(cx, cy, 1),
                              coarse.normal.at(cx, cy, 2));
      const Eigen::Vector3d X = coarse_cam.PixelToCamera(cx + 0.5, cy + 0.5, d);
      const Eigen::Vector3d ray = fine_cam.PixelToCamera(x + 0.5, y + 0.5, 1.0);
      const double denom = n.dot(ray);
      if (!(denom < 0)) continue;
      const double fine_depth = n.dot(X) / denom;
      if (!std::isfinite(fine_depth) || fine_depth <= 0) continue;
      fine.depth.at(x, y) = static_cast<float>(fine_depth);
      for (int c = 0; c < 3; ++c) fine.normal.at(x, y, c) = static_cast<float>(n[c]);
    }
  }
  return fine;
}

}  // namespace

Eigen::Matrix3d PlaneHomography(const PinholeCamera& ref, const PinholeCamera& src,
                                const Eigen::Vector3d& normal, double u, double v,
                                double depth) {
  const Eigen::Matrix3d R = src.R * ref.R.transpose();
  const Eigen::Vector3d t = src.t - R * ref.t;
  const Eigen::Vector3d X = ref.PixelToCamera(u, v, depth);
  const double d = normal.dot(X);
  return src.K() * (R + t * normal.transpose() / d) * ref.K().inverse();
}

DepthNormalMap PatchMatchView(const std::vector<StereoView>& views, int ref,
                              const std::vector<int>& sources,
                              const PatchMatchOptions& options,
                              const std::vector<const Image*>* source_depths,
                              const DepthNormalMap* init) {
  options.Check();
  Require(ref >= 0 && ref < static_cast<int>(views.size()), "PatchMatchStereo",
          "reference view index out of range");
  const StereoView& rv = views[ref];
  CheckView(rv, "reference view");
  Require(!sources.empty(), rv.name, "no source views");
  Require(sources.size() <= 64, rv.name, "more than 64 source views");
  Require(rv.depth_min > 0 && rv.depth_max > rv.depth_min && std::isfinite(rv.depth_max),
          rv.name, "invalid depth range");
  for (int s : sources) {
    Require(s >= 0 && s < static_cast<int>(views.size()) && s != ref, rv.name,
            "source view index out of range");
    CheckView(views[s], "source view");
  }
  if (source_depths) {
    Require(source_depths->size() == sources.size(), rv.name,
            "one depth map per source view needed for the geometric pass");
    for (size_t i = 0; i < sources.size(); ++i) {
      const Image* d = (*source_depths)[i];
      Require(d && d->channels == 1 && d->width == views[sources[i]].camera.width &&
                  d->height == views[sources[i]].camera.height,
              views[sources[i]].name, "depth map does not match the camera size");
    }
  }
  if (init) {
    Require(init->depth.width == rv.camera.width &&
                init->depth.height == rv.camera.height && init->depth.channels == 1 &&
                init->normal.channels == 3 && init->normal.width == rv.camera.width &&
                init->normal.height == rv.camera.height,
            rv.name, "initial depth/normal map does not match the camera size");
  }
  int iterations =
      source_depths ? options.num_geometric_iterations : options.num_iterations;
  int first_iteration = source_depths ? 2 : 0;
  DepthNormalMap coarse_init;
  const int small_side = std::min(rv.camera.width, rv.camera.height);
  if (!source_depths && !init && options.num_coarse_levels > 0 &&
      small_side >= 2 * kMinCoarseSide) {
    coarse_init = SolveCoarse(views, ref, sources, options);
    init = &coarse_init;
    iterations = options.num_fine_iterations;
    first_iteration = options.num_iterations;
  }
  ViewSolver solver(views, ref, sources, options, source_depths);
  solver.Initialize(init);
  solver.Iterate(iterations, first_iteration, init != nullptr);
  return solver.Result();
}

}  // namespace fvs::mvs
