#include "tools/headroom/choice_evidence.h"

#include <iomanip>
#include <iostream>
#include <sstream>

#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "tools/headroom/consensus.h"

namespace fvs {
namespace {

namespace F = torch::nn::functional;

// Finite difference along dim (replicating the last one), for the Jacobian.
torch::Tensor Diff(const torch::Tensor& x, int64_t dim) {
  const int64_t n = x.size(dim);
  if (n < 2) return torch::zeros_like(x);
  const torch::Tensor d = x.narrow(dim, 1, n - 1) - x.narrow(dim, 0, n - 1);
  return torch::cat({d, d.narrow(dim, n - 2, 1)}, dim);
}

// Source pixel positions [K,h,w] (pixel i spans [i, i+1]); far outside where the grid is
// not finite.
std::pair<torch::Tensor, torch::Tensor> SourcePositions(const torch::Tensor& grid,
                                                        int64_t width, int64_t height) {
  const torch::Tensor g =
      torch::nan_to_num(grid, -100.0, -100.0, -100.0).clamp(-100, 100);
  return {(g.select(3, 0) + 1) * (0.5 * width), (g.select(3, 1) + 1) * (0.5 * height)};
}

// 4 log(d / z): the source's own depth at the sample against the depth the target's
// point has in the source; 0 where the target pixel has no surface. Negative: the
// source sees something nearer (an occluder or a mesh that is off).
torch::Tensor OcclusionResidual(const torch::Tensor& source_depths,  // [K,1,H,W]
                                const torch::Tensor& grid, const torch::Tensor& z) {
  const torch::Tensor d =
      F::grid_sample(source_depths, torch::nan_to_num(grid, -2, -2, -2),
                     F::GridSampleFuncOptions()
                         .mode(torch::kNearest)
                         .padding_mode(torch::kZeros)
                         .align_corners(false));
  const torch::Tensor r =
      (4 * torch::log(d.clamp_min(1e-6) / z.clamp_min(1e-6))).clamp(-2, 2);
  return torch::where(z > 0, r, torch::zeros_like(r));
}

// Gradient energy of each source's luminance in its own image, 5x5 mean, log; sampled at
// the warp (its texture before warping: blur and detail of that photo there).
torch::Tensor SourceSharpness(const torch::Tensor& source_rgb,
                              const torch::Tensor& grid) {
  const torch::Tensor lum = ((source_rgb + 1) * 0.5).mean(1, true);  // [K,1,H,W]
  const torch::Tensor energy = BoxMeanInImage(Diff(lum, 3).abs() + Diff(lum, 2).abs(), 2);
  return F::grid_sample(torch::log(energy + 1e-3), torch::nan_to_num(grid, -2, -2, -2),
                        F::GridSampleFuncOptions()
                            .mode(torch::kBilinear)
                            .padding_mode(torch::kBorder)
                            .align_corners(false));
}

// Mean of x [K,1,h,w] over the pixels each source sees, broadcast back: [K,1,h,w].
torch::Tensor MeanOverSeen(const torch::Tensor& x, const torch::Tensor& seen) {
  const torch::Tensor mean =
      (x * seen).sum({2, 3}, true) / seen.sum({2, 3}, true).clamp_min(1);
  return mean.expand_as(x);
}

// x less its mean over the sources that see each pixel.
torch::Tensor RelativeToSeeing(const torch::Tensor& x, const torch::Tensor& seen) {
  const torch::Tensor mean = (x * seen).sum(0, true) / seen.sum(0, true).clamp_min(1);
  return (x - mean) * seen;
}

}  // namespace

const char* EvidenceChannelName(int channel) {
  static const char* const kNames[kNumEvidence] = {
      "ulr_log_weight",   "occlusion",
      "occlusion_abs",    "footprint",
      "footprint_coarse", "border",
      "sharpness",        "blend_distance5",
      "blend_distance",   "seen_share",
      "surface",          "coverage",
      "global_sharpness", "global_blend_distance"};
  return channel >= 0 && channel < kNumEvidence ? kNames[channel] : "?";
}

torch::Tensor SourceEvidence(const PackedScene& scene, const TrainingSample& s,
                             const torch::Tensor& colours) {
  torch::NoGradGuard no_grad;
  const torch::Tensor& seen = s.warp.valid_warp;
  const int64_t k = seen.size(0), h = seen.size(2), w = seen.size(3);
  const int64_t sh = s.source_rgb.size(2), sw = s.source_rgb.size(3);
  const torch::Tensor idx =
      torch::tensor(std::vector<int64_t>(s.sources.begin(), s.sources.end()));
  const torch::Tensor depths = scene.depths.index_select(0, idx).unsqueeze(1);
  std::vector<torch::Tensor> ch(kNumEvidence);

  const torch::Tensor lw = s.warp.ulr_log_weights + (seen - 1) * 1e4;
  ch[kEvidenceUlrLogWeight] = ((lw - lw.amax(0, true)).clamp(-8, 0) / 4) * seen;
  ch[kEvidenceOcclusion] = OcclusionResidual(depths, s.warp.grid, s.warp.source_z) * seen;
  ch[kEvidenceOcclusionAbs] = ch[kEvidenceOcclusion].abs();
  const auto [u, v] = SourcePositions(s.warp.grid, sw, sh);
  const torch::Tensor det =
      (Diff(u, 2) * Diff(v, 1) - Diff(u, 1) * Diff(v, 2)).abs().unsqueeze(1);
  ch[kEvidenceFootprint] = (0.5 * torch::log(det + 1e-6)).clamp(-3, 3) * seen;
  ch[kEvidenceFootprintCoarse] = ch[kEvidenceFootprint].clamp_min(0);
  const torch::Tensor border =
      torch::minimum(torch::minimum(u, sw - u), torch::minimum(v, sh - v)).unsqueeze(1);
  ch[kEvidenceBorder] = (border / 16).clamp(0, 1) * seen;
  const torch::Tensor sharpness = SourceSharpness(s.source_rgb, s.warp.grid);
  ch[kEvidenceSharpness] = RelativeToSeeing(sharpness, seen).clamp(-4, 4);
  const torch::Tensor blend = BlendSeen(colours, seen, s.warp.ulr_log_weights);
  const torch::Tensor distance = (colours - blend).abs().mean(1, true) * seen;
  ch[kEvidenceBlendDistance] = (10 * distance).clamp(0, 4);
  ch[kEvidenceBlendDistance5] = (10 * BoxMeanInImage(distance, 2)).clamp(0, 4) * seen;
  ch[kEvidenceSeenShare] = (seen.sum(0, true) / k).expand({k, 1, h, w}) * seen;
  ch[kEvidenceSurface] = s.warp.valid_depth.expand({k, 1, h, w}) * seen;
  ch[kEvidenceCoverage] = seen.mean({2, 3}, true).expand({k, 1, h, w}) * seen;
  const torch::Tensor global_sharpness = MeanOverSeen(sharpness, seen);
  ch[kEvidenceGlobalSharpness] =
      ((global_sharpness - global_sharpness.mean(0, true)) * seen).clamp(-4, 4);
  ch[kEvidenceGlobalBlendDistance] =
      (10 * MeanOverSeen(distance, seen)).clamp(0, 4) * seen;
  return torch::nan_to_num(torch::cat(ch, 1), 0, 0, 0);
}

ChoiceModelImpl::ChoiceModelImpl(int hidden_units, bool local_only)
    : hidden(hidden_units) {
  channel_mask = torch::ones({kNumEvidence});
  if (local_only)
    channel_mask.narrow(0, kEvidenceCoverage, kNumEvidence - kEvidenceCoverage).zero_();
  channel_mask = register_buffer("channel_mask", channel_mask);
  const int64_t out_of_first = hidden > 0 ? hidden : 1;
  first = register_module("first", torch::nn::Linear(kNumEvidence, out_of_first));
  torch::Tensor last_weight = first->weight;
  if (hidden > 0) {
    second = register_module("second", torch::nn::Linear(hidden, 1));
    last_weight = second->weight;
  }
  torch::NoGradGuard no_grad;
  last_weight.zero_();
  (hidden > 0 ? second->bias : first->bias).zero_();
}

torch::Tensor ChoiceModelImpl::forward(const torch::Tensor& evidence,
                                       const torch::Tensor& ulr_log_weights) {
  torch::Tensor x = evidence.movedim(1, -1) * channel_mask;  // [K,...,F]
  x = first->forward(x);
  if (hidden > 0) x = second->forward(torch::relu(x));
  return ulr_log_weights + x.movedim(-1, 1);
}

std::vector<ChoiceFitOptions> ParseChoiceSpecs(const std::string& specs) {
  std::vector<ChoiceFitOptions> fits;
  std::stringstream list(specs);
  std::string spec;
  while (std::getline(list, spec, ',')) {
    if (spec.empty()) continue;
    std::stringstream parts(spec);
    std::string hidden, loss, channels, extra;
    std::getline(parts, hidden, ':');
    std::getline(parts, loss, ':');
    std::getline(parts, channels, ':');
    const bool digits = !hidden.empty() && hidden.size() <= 4 &&
                        hidden.find_first_not_of("0123456789") == std::string::npos;
    Require(digits && (loss == "l1" || loss == "l2") &&
                (channels == "all" || channels == "local") && !std::getline(parts, extra),
            "--Train.headroom_choice",
            "'" + spec + "' is not HIDDEN:l1|l2:all|local (e.g. 16:l2:local)");
    ChoiceFitOptions fit;
    fit.hidden = std::stoi(hidden);
    fit.squared_error = loss == "l2";
    fit.local_only = channels == "local";
    fits.push_back(fit);
  }
  return fits;
}

std::string ChoiceSpecName(const ChoiceFitOptions& fit) {
  return "choice_h" + std::to_string(fit.hidden) + (fit.squared_error ? "_l2" : "_l1") +
         (fit.local_only ? "_local" : "_all");
}

ChoiceFit FitChoiceModel(const std::vector<PackedScene>& scenes, int num_sources,
                         const SampleWarpOptions& warp, bool holdout_targets,
                         const ChoiceFitOptions& options, bool quiet) {
  torch::manual_seed(options.seed);
  SampleWarpOptions settings = warp;
  settings.ulr_log_weights = true;
  std::vector<torch::Tensor> ev, col, seen, lw, photo;
  for (const PackedScene& scene : scenes) {
    for (const int target :
         ValidationTargets(scene, scene.num_views(), holdout_targets)) {
      const auto sources = SelectTrainingSources(scene, target, num_sources);
      if (static_cast<int>(sources.size()) < num_sources) continue;
      const TrainingSample s = MakeSample(scene, target, sources, 0, 0, scene.width(),
                                          scene.height(), settings);
      const torch::Tensor c = (WarpFeatures(s.source_rgb, s.warp.grid) + 1) * 0.5;
      const torch::Tensor e = SourceEvidence(scene, s, c);
      const torch::Tensor covered =
          (s.warp.valid_warp.sum(0).flatten() > 0).nonzero().flatten();
      if (covered.numel() == 0) continue;
      const torch::Tensor pick = covered.index_select(
          0, torch::randint(covered.numel(), {options.pixels_per_view}, torch::kLong));
      const auto take = [&](const torch::Tensor& x) {  // [K,C,h,w] -> [K,C,P]
        return x.flatten(2).index_select(2, pick);
      };
      ev.push_back(take(e));
      col.push_back(take(c));
      seen.push_back(take(s.warp.valid_warp));
      lw.push_back(take(s.warp.ulr_log_weights));
      photo.push_back(take(s.target_rgb));
    }
  }
  ChoiceFit fit;
  fit.model = ChoiceModel(options.hidden, options.local_only);
  if (ev.empty()) return fit;
  const torch::Tensor e = torch::cat(ev, 2), c = torch::cat(col, 2),
                      v = torch::cat(seen, 2), l = torch::cat(lw, 2),
                      p = torch::cat(photo, 2);
  fit.pixels = p.size(2);
  torch::optim::Adam adam(fit.model->parameters(),
                          torch::optim::AdamOptions(options.learning_rate));
  for (int step = 0; step <= options.steps; ++step) {
    adam.zero_grad();
    const torch::Tensor blend = BlendSeen(c, v, fit.model->forward(e, l));
    const torch::Tensor loss =
        options.squared_error ? (blend - p).pow(2).mean() : (blend - p).abs().mean();
    fit.final_error = loss.item<double>();
    if (step == 0) fit.start_error = fit.final_error;
    if (step % 100 == 0 && !quiet) {
      std::cerr << "[choice] hidden " << options.hidden << " step " << step << " of "
                << options.steps << (options.squared_error ? ": squared error " : ": L1 ")
                << std::setprecision(5) << fit.final_error << " on " << p.size(2)
                << " pixels\n";
    }
    if (step == options.steps) break;
    loss.backward();
    adam.step();
  }
  fit.model->eval();
  return fit;
}

}  // namespace fvs
