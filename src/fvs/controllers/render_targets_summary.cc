// PrintRenderTargetsSummary (render_targets.h): what `colmap view_synthesis` prints at
// the end of a render.
#include <algorithm>
#include <cstdio>

#include "fvs/controllers/render_targets.h"

namespace fvs {
namespace {

void PrintTimings(const RenderTargetsResult& result) {
  std::printf("%-24s %8s %8s %8s %8s %8s %8s %9s\n", "target", "total_s", "depth_s",
              "select_s", "warp_s", "encode_s", "blend_s", "coverage");
  const std::vector<RenderedFrame>& rendered = result.frames.rendered;
  RenderTimings sum;
  for (const RenderedFrame& frame : rendered) {
    const RenderTimings& t = frame.timings;
    std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1f%%\n",
                result.target_names[frame.index].c_str(), t.total(), t.depth_s,
                t.selection_s, t.warp_s, t.encode_s, t.blend_s, 100 * frame.coverage);
    sum.depth_s += t.depth_s;
    sum.selection_s += t.selection_s;
    sum.warp_s += t.warp_s;
    sum.encode_s += t.encode_s;
    sum.blend_s += t.blend_s;
  }
  const double n = static_cast<double>(std::max<size_t>(1, rendered.size()));
  std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f\n", "mean", sum.total() / n,
              sum.depth_s / n, sum.selection_s / n, sum.warp_s / n, sum.encode_s / n,
              sum.blend_s / n);
}

void PrintFrameSummary(const RenderTargetsOptions& options,
                       const FrameReportSummary& summary) {
  std::printf("frames: %d, mean coverage %.1f%%, %zu flagged under %.0f%%%s\n",
              summary.num_frames, 100 * summary.mean_coverage, summary.flagged.size(),
              100 * options.temporal.coverage_threshold,
              summary.flagged.empty() ? "" : " (see frame_report.csv)");
  if (summary.mean_flicker >= 0) {
    std::printf(
        "flicker: %.3f levels (mean |frame t+1 - warped frame t|, 8-bit), %.2f "
        "source changes per frame, %.1f ms per frame (%.1f ms of it temporal "
        "blend + flicker)\n",
        summary.mean_flicker, summary.mean_source_changes, 1000 * summary.mean_seconds,
        1000 * summary.mean_temporal_seconds);
  }
  if (summary.num_psnr > 0) {
    std::printf("ground truth: PSNR %.2f dB over %d of %d frames (%s)\n",
                summary.mean_psnr, summary.num_psnr, summary.num_frames,
                options.ground_truth_path.c_str());
  } else if (!options.ground_truth_path.empty()) {
    std::printf("ground truth: no frame has an image in %s\n",
                options.ground_truth_path.c_str());
  }
}

}  // namespace

void PrintRenderTargetsSummary(const RenderTargetsOptions& options,
                               const RenderTargetsResult& result) {
  if (result.shard_empty) return;
  std::printf("scene: %d views, loaded in %.2f s (%d source depths computed)\n",
              result.num_views, result.scene_load_seconds, result.num_depths_computed);
  PrintTimings(result);
  const size_t num_rendered = result.frames.rendered.size();
  std::printf("wrote %zu images to %s (%zu resumed)\n", num_rendered,
              options.output_path.c_str(), result.target_names.size() - num_rendered);
  PrintFrameSummary(options, result.frames.summary);
  if (result.has_video) {
    std::printf("%s%s\n",
                result.video.written ? "" : "NOTE: ", result.video.note.c_str());
  }
}

}  // namespace fvs
