#include "tools/headroom/consensus.h"

#include "fvs/net/net.h"

namespace fvs {
namespace F = torch::nn::functional;
namespace {

// x [K,C,H,W], padded by `pad` on every side, shifted so that out(y, x) = x(y + dy,
// x + dx); where that falls outside x, the padding's values.
torch::Tensor Shifted(const torch::Tensor& padded, int pad, int dy, int dx,
                      int64_t height, int64_t width) {
  return padded.narrow(2, pad + dy, height).narrow(3, pad + dx, width);
}

}  // namespace

torch::Tensor BoxMean(const torch::Tensor& x, int radius) {
  if (radius <= 0) return x;
  const torch::Tensor padded = F::pad(
      x, F::PadFuncOptions({radius, radius, radius, radius}).mode(torch::kReplicate));
  return F::avg_pool2d(padded, F::AvgPool2dFuncOptions(2 * radius + 1).stride(1));
}

torch::Tensor SeenWeights(const torch::Tensor& log_weights, const torch::Tensor& seen) {
  const torch::Tensor w = SoftmaxWeights(log_weights + (seen - 1) * 1e4) * seen;
  return w / w.sum(0, true).clamp_min(1e-12);
}

torch::Tensor BlendSeen(const torch::Tensor& colours, const torch::Tensor& seen,
                        const torch::Tensor& log_weights) {
  return (SeenWeights(log_weights, seen) * colours).sum(0, true);
}

torch::Tensor BoxMeanInImage(const torch::Tensor& x, int radius) {
  if (radius <= 0) return x;
  return F::avg_pool2d(x, F::AvgPool2dFuncOptions(2 * radius + 1)
                              .stride(1)
                              .padding(radius)
                              .count_include_pad(false));
}

torch::Tensor ConsensusLogWeights(const torch::Tensor& colours, const torch::Tensor& seen,
                                  const torch::Tensor& log_weights,
                                  const ConsensusOptions& options) {
  torch::Tensor term = torch::zeros_like(log_weights);
  if (options.tau <= 0) return term;
  const double scale = 1.0 / (2.0 * options.tau * options.tau);
  // Where a source sees nothing of the window its distance is the window's mean of
  // nothing: 0 over a floor, and its weight is already e^-9 there (the ULR floor).
  const torch::Tensor coverage = BoxMean(seen, options.radius).clamp_min(1e-3);
  for (int i = 0; i < options.iterations; ++i) {
    const torch::Tensor blend = BlendSeen(colours, seen, log_weights + term);
    const torch::Tensor d =
        BoxMean((colours - blend).pow(2).mean(1, true) * seen, options.radius) / coverage;
    term = -(d * scale).clamp_max(30.0);
  }
  return term;
}

void AlignToBlend(torch::Tensor* colours, torch::Tensor* seen,
                  const torch::Tensor& log_weights, const AlignOptions& options) {
  if (options.search <= 0) return;
  const int r = options.search;
  const int64_t h = colours->size(2), w = colours->size(3);
  for (int it = 0; it < options.iterations; ++it) {
    const torch::Tensor blend = BlendSeen(*colours, *seen, log_weights);
    const torch::Tensor pc =
        F::pad(*colours, F::PadFuncOptions({r, r, r, r}).mode(torch::kReplicate));
    const torch::Tensor ps = F::pad(*seen, F::PadFuncOptions({r, r, r, r}));
    torch::Tensor best_cost, best_colour, best_seen;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const torch::Tensor c = Shifted(pc, r, dy, dx, h, w);
        const torch::Tensor s = Shifted(ps, r, dy, dx, h, w);
        // Mean squared difference over the window's pixels the source sees there.
        const torch::Tensor cost =
            BoxMean((c - blend).pow(2).mean(1, true) * s, options.window) /
                BoxMean(s, options.window).clamp_min(1e-3) +
            options.penalty * (dx * dx + dy * dy) + (1 - s) * 1e3;
        if (!best_cost.defined()) {
          best_cost = cost, best_colour = c.clone(), best_seen = s.clone();
          continue;
        }
        const torch::Tensor better = cost < best_cost;
        best_cost = torch::where(better, cost, best_cost);
        best_colour = torch::where(better, c, best_colour);
        best_seen = torch::where(better, s, best_seen);
      }
    }
    // A pixel the source did not see before stays unseen: the shift only corrects where
    // a seen surface lands.
    *seen = best_seen * *seen;
    *colours = best_colour;
  }
}

}  // namespace fvs
