#include "tools/headroom/headroom.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "fvs/net/net.h"
#include "fvs/train/loss.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "tools/headroom/consensus.h"
#include "tools/headroom/depth_stereo.h"
#include "tools/headroom/depth_sweep.h"

namespace fvs {
namespace {

double Psnr(const torch::Tensor& a, const torch::Tensor& b) {
  const double mse = (a - b).pow(2).mean().item<double>();
  return 10.0 * std::log10(1.0 / std::max(mse, 1e-10));
}

// Each pixel: the seeing source whose colour is closest (L1 over channels) to the photo.
torch::Tensor PixelOracle(const torch::Tensor& colours, const torch::Tensor& seen,
                          const torch::Tensor& photo) {
  const torch::Tensor error =
      (colours - photo).abs().sum(1, true) + (1 - seen) * 1e6;  // [K,1,H,W]
  const torch::Tensor best = error.argmin(0, true);             // [1,1,H,W]
  return colours.gather(0, best.expand({1, 3, -1, -1}));
}

// K global weights (softmax of free parameters) fitted to the photo on the covered
// pixels.
torch::Tensor GlobalOracle(const torch::Tensor& colours, const torch::Tensor& seen,
                           const torch::Tensor& photo, const torch::Tensor& covered) {
  const int64_t k = colours.size(0);
  torch::Tensor logits = torch::zeros({k, 1, 1, 1}, torch::requires_grad());
  torch::optim::Adam adam({logits}, torch::optim::AdamOptions(0.1));
  for (int i = 0; i < 150; ++i) {
    adam.zero_grad();
    const torch::Tensor blend = BlendSeen(colours, seen, logits.expand_as(seen));
    const torch::Tensor loss = ((blend - photo).pow(2) * covered).mean();
    loss.backward();
    adam.step();
  }
  torch::NoGradGuard no_grad;
  return BlendSeen(colours, seen, logits.expand_as(seen));
}

// Each 8x8 block: the one seeing source whose colours are closest to the photo over the
// block (pixels it does not see keep `fallback`). What a choice that cannot follow noise
// pixel by pixel could gain.
torch::Tensor PatchOracle(const torch::Tensor& colours, const torch::Tensor& seen,
                          const torch::Tensor& photo, const torch::Tensor& fallback) {
  namespace F = torch::nn::functional;
  const int64_t h = colours.size(2), w = colours.size(3);
  const torch::Tensor error = (colours - photo).abs().sum(1, true) + (1 - seen) * 3.0;
  const torch::Tensor block = F::avg_pool2d(
      error, F::AvgPool2dFuncOptions(8).ceil_mode(true).count_include_pad(false));
  const torch::Tensor best = F::interpolate(block.argmin(0, true).to(torch::kFloat),
                                            F::InterpolateFuncOptions()
                                                .size(std::vector<int64_t>{h, w})
                                                .mode(torch::kNearest))
                                 .to(torch::kLong);
  const torch::Tensor chosen = colours.gather(0, best.expand({1, 3, -1, -1}));
  const torch::Tensor chosen_seen = seen.gather(0, best);
  return torch::where(chosen_seen > 0.5, chosen, fallback);
}

// Blends that see no photo: the ULR weights with the colour-consensus term
// (consensus.h) at a few settings.
const ConsensusOptions kConsensus[] = {{0.1, 2, 1}, {0.15, 2, 1}};

// The sources aligned to the blend by local shifts, then blended with the ULR weights.
const AlignOptions kAlign[] = {{2, 2, 1e-3, 1}};

// The proxy's depth refined per pixel where the sources agree best
// (tools/headroom/depth_sweep.h).
const DepthSweepOptions kSweep[] = {
    {3, 0.03, 2, 1e-4, 0}, {4, 0.06, 3, 1e-4, 0}, {2, 0.02, 4, 1e-4, 0.5}};

// The same by per-view stereo: correlation cost, semi-global matching
// (tools/headroom/depth_stereo.h).
// Settings chosen on two held-out views each of fold 0 of four training scenes; the
// widest (+-3 %) with a large prior, and +-1 %.
const DepthStereoOptions kStereo[] = {{4, 0.03, 3, 0.02, 0.3, 0.2, 1.0, 0.5},
                                      {2, 0.01, 3, 0.01, 0.1, 0.1, 0.6, 0.5}};

std::vector<std::string> MethodNames(const std::vector<NamedChoiceModel>& choice) {
  std::vector<std::string> names = {"ulr", "oracle_pixel", "oracle_global",
                                    "oracle_patch8", "oracle_colour"};
  for (const ConsensusOptions& c : kConsensus) {
    std::ostringstream name;
    name << "consensus_t" << c.tau << "_r" << c.radius << "_i" << c.iterations;
    names.push_back(name.str());
  }
  for (const AlignOptions& a : kAlign) {
    std::ostringstream name;
    name << "align_s" << a.search << "_w" << a.window << "_p" << a.penalty << "_i"
         << a.iterations;
    names.push_back(name.str());
  }
  for (const DepthSweepOptions& d : kSweep) {
    std::ostringstream name;
    name << "sweep_" << d.max_relative * 100 << "pc_s" << d.steps << "_r" << d.radius;
    if (d.relative_prior > 0) name << "_rel" << d.relative_prior;
    names.push_back(name.str());
  }
  for (const DepthStereoOptions& d : kStereo) {
    std::ostringstream name;
    name << "stereo_" << d.max_relative * 100 << "pc_s" << d.steps << "_r" << d.radius
         << "_p" << d.prior << "_" << d.p1 << "_" << d.p2 << "_a" << d.absolute_weight;
    names.push_back(name.str());
  }
  names.push_back("exposure_gain");
  names.push_back("exposure_affine");
  for (const NamedChoiceModel& c : choice) names.push_back(c.name);
  return names;
}

// The ULR blend with one affine colour transform per channel (gain and offset) fitted to
// the photo on the covered pixels by least squares: how much of the error is a global
// colour or exposure difference between the sources and the photo, which no blender can
// know without the photo.
torch::Tensor ColourOracle(const torch::Tensor& blend, const torch::Tensor& photo,
                           const torch::Tensor& covered) {
  const torch::Tensor n = covered.sum().clamp_min(1.0);
  const torch::Tensor mx = (blend * covered).sum({0, 2, 3}, true) / n;
  const torch::Tensor my = (photo * covered).sum({0, 2, 3}, true) / n;
  const torch::Tensor dx = (blend - mx) * covered, dy = (photo - my) * covered;
  const torch::Tensor gain =
      (dx * dy).sum({0, 2, 3}, true) / (dx * dx).sum({0, 2, 3}, true).clamp_min(1e-9);
  return (blend - mx) * gain + my;
}

// Photo-free exposure matching: every source's colours mapped by one gain per channel
// (and an offset, with `affine`) onto those of the anchor source, the one with the most
// ULR weight over the view (the nearest), fitted on the pixels both see; then the ULR
// blend. If a novel view is exposed like its nearest photo, the other photos' exposure
// differences are what the blend should not mix in.
torch::Tensor ExposureMatchedBlend(const torch::Tensor& colours,
                                   const torch::Tensor& seen,
                                   const torch::Tensor& ulr_log_weights, bool affine) {
  const int64_t anchor =
      (SoftmaxWeights(ulr_log_weights) * seen).sum({1, 2, 3}).argmax().item<int64_t>();
  const torch::Tensor a = colours[anchor].unsqueeze(0);
  const torch::Tensor both = seen * seen[anchor].unsqueeze(0);  // [K,1,H,W]
  const torch::Tensor n = both.sum({2, 3}, true).clamp_min(1.0);
  torch::Tensor matched;
  if (affine) {
    const torch::Tensor mc = (colours * both).sum({2, 3}, true) / n;
    const torch::Tensor ma = (a * both).sum({2, 3}, true) / n;
    const torch::Tensor dc = (colours - mc) * both, da = (a - ma) * both;
    const torch::Tensor gain =
        ((dc * da).sum({2, 3}, true) / (dc * dc).sum({2, 3}, true).clamp_min(1e-9))
            .clamp(0.5, 2.0);
    matched = (colours - mc) * gain + ma;
  } else {
    const torch::Tensor gain =
        ((colours * a * both).sum({2, 3}, true) /
         (colours * colours * both).sum({2, 3}, true).clamp_min(1e-9))
            .clamp(0.5, 2.0);
    matched = colours * gain;
  }
  // A source sharing fewer than 1 % of the pixels with the anchor keeps its colours.
  const torch::Tensor enough =
      (both.sum({2, 3}, true) > 0.01 * colours.size(2) * colours.size(3));
  matched = torch::where(enough, matched, colours);
  return BlendSeen(matched.clamp(0, 1), seen, ulr_log_weights);
}

// Whether `name` starts with one of the comma-separated prefixes of `methods` (all when
// empty).
bool Selected(const std::string& name, const std::string& methods) {
  if (methods.empty()) return true;
  std::istringstream list(methods);
  std::string prefix;
  while (std::getline(list, prefix, ',')) {
    if (!prefix.empty() && name.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

}  // namespace

std::vector<HeadroomRow> MeasureHeadroom(const std::vector<PackedScene>& scenes,
                                         int num_sources, int views_per_scene,
                                         const SampleWarpOptions& warp_settings,
                                         const ImageDistance& lpips, bool holdout_targets,
                                         const std::vector<NamedChoiceModel>& choice,
                                         const std::string& methods) {
  const std::vector<std::string> kMethods = MethodNames(choice);
  const int kNum = static_cast<int>(kMethods.size());
  std::vector<bool> selected(kNum);
  for (int m = 0; m < kNum; ++m) selected[m] = Selected(kMethods[m], methods);
  Require(std::find(selected.begin(), selected.end(), true) != selected.end(),
          "--Train.headroom_methods", "'" + methods + "' selects no method");
  std::vector<HeadroomRow> rows, all(kNum);
  const double no_lpips = lpips ? 0.0 : -1.0;
  for (int m = 0; m < kNum; ++m) all[m] = {"all", kMethods[m], 0, 0, 0, no_lpips};
  SampleWarpOptions settings = warp_settings;
  settings.ulr_log_weights = true;
  for (const PackedScene& scene : scenes) {
    std::vector<HeadroomRow> mine(kNum);
    for (int m = 0; m < kNum; ++m) mine[m] = {scene.path, kMethods[m], 0, 0, 0, no_lpips};
    for (const int target : ValidationTargets(scene, views_per_scene, holdout_targets)) {
      const auto sources = SelectTrainingSources(scene, target, num_sources);
      if (sources.empty()) continue;
      const TrainingSample s = MakeSample(scene, target, sources, 0, 0, scene.width(),
                                          scene.height(), settings);
      torch::NoGradGuard no_grad;
      const torch::Tensor colours = (WarpFeatures(s.source_rgb, s.warp.grid) + 1) * 0.5;
      const torch::Tensor seen = s.warp.valid_warp;
      const torch::Tensor covered = (seen.sum(0, true) > 0).to(torch::kFloat);
      const torch::Tensor ulr = BlendSeen(colours, seen, s.warp.ulr_log_weights);
      // The methods' images in the order of kMethods; unselected ones stay undefined.
      std::vector<torch::Tensor> images;
      const auto add = [&](const std::function<torch::Tensor()>& render) {
        images.push_back(selected[images.size()] ? render() : torch::Tensor());
      };
      add([&] { return ulr; });
      add([&] { return PixelOracle(colours, seen, s.target_rgb); });
      add([&] {
        torch::AutoGradMode grad(true);  // the global oracle is fitted by Adam
        return GlobalOracle(colours, seen, s.target_rgb, covered);
      });
      add([&] { return PatchOracle(colours, seen, s.target_rgb, ulr); });
      add([&] { return ColourOracle(ulr, s.target_rgb, covered); });
      for (const ConsensusOptions& c : kConsensus) {
        add([&] {
          const torch::Tensor log_weights = s.warp.ulr_log_weights;
          return BlendSeen(
              colours, seen,
              log_weights + ConsensusLogWeights(colours, seen, log_weights, c));
        });
      }
      for (const AlignOptions& a : kAlign) {
        add([&] {
          torch::Tensor aligned = colours, aligned_seen = seen;
          AlignToBlend(&aligned, &aligned_seen, s.warp.ulr_log_weights, a);
          return BlendSeen(aligned, aligned_seen, s.warp.ulr_log_weights);
        });
      }
      for (const DepthSweepOptions& d : kSweep) {
        add([&] { return DepthSweepBlend(scene, s, settings, d); });
      }
      for (const DepthStereoOptions& d : kStereo) {
        add([&] { return DepthStereoBlend(scene, s, settings, d); });
      }
      add([&] {
        return ExposureMatchedBlend(colours, seen, s.warp.ulr_log_weights, false);
      });
      add([&] {
        return ExposureMatchedBlend(colours, seen, s.warp.ulr_log_weights, true);
      });
      torch::Tensor evidence;  // for the choice rows; only when one is selected
      for (NamedChoiceModel c : choice) {  // a holder: a shared pointer
        add([&] {
          if (!evidence.defined()) evidence = SourceEvidence(scene, s, colours);
          return BlendSeen(colours, seen,
                           c.model->forward(evidence, s.warp.ulr_log_weights));
        });
      }
      for (int m = 0; m < kNum; ++m) {
        if (!images[m].defined()) continue;
        const torch::Tensor filled =
            FillHolesOf(images[m].clamp(0, 1), covered, s.warp.valid_depth);
        HeadroomRow& r = mine[m];
        r.psnr += Psnr(filled, s.target_rgb);
        r.ssim += Ssim(filled, s.target_rgb).item<double>();
        if (lpips) r.lpips += lpips(filled, s.target_rgb);
        ++r.views;
      }
    }
    for (int m = 0; m < kNum; ++m) {
      HeadroomRow& r = mine[m];
      if (r.views == 0) continue;
      all[m].views += r.views;
      all[m].psnr += r.psnr;
      all[m].ssim += r.ssim;
      if (lpips) all[m].lpips += r.lpips;
      r.psnr /= r.views;
      r.ssim /= r.views;
      if (lpips) r.lpips /= r.views;
      rows.push_back(r);
    }
  }
  for (HeadroomRow& r : all) {
    if (r.views == 0) continue;
    r.psnr /= r.views;
    r.ssim /= r.views;
    if (lpips) r.lpips /= r.views;
    rows.push_back(r);
  }
  return rows;
}

void WriteHeadroomCsv(const std::string& path, const std::vector<HeadroomRow>& rows) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << "scene,method,views,psnr,ssim,lpips\n";
    for (const HeadroomRow& r : rows) {
      out << r.scene << "," << r.method << "," << r.views << "," << r.psnr << ","
          << r.ssim << ",";
      if (r.lpips >= 0) out << r.lpips;
      out << "\n";
    }
  });
}

}  // namespace fvs
