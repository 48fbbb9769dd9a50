// Rendering a sequence of frames with temporal stability, around any Method:
//   - source hysteresis: the previous frame's sources go in TargetView::preferred_sources
//     (RenderOptions::source_hysteresis decides how strongly they are kept);
//   - temporal blend: the output is mixed with the previous output warped into this frame
//     (target depths and poses, occlusion-checked: flicker.h) where both see the surface,
//     weight `temporal_blend` for the previous frame;
//   - the flicker of every frame to the previous one, for the per-frame report.
// A frame that is not rendered (resumed from disk) breaks the chain: Reset(), or
// Remember() it (re-rendered, with its colour from disk) so that the chain goes on.
#pragma once

#include <vector>

#include "fvs/path/flicker.h"
#include "fvs/path/frame_report.h"
#include "fvs/render/method.h"

namespace fvs {

struct TemporalOptions {
  double temporal_blend = 0;  // in [0, 1): share of the warped previous output
  bool use_preferred_sources = true;
  double coverage_threshold = 0.5;  // frames under it are flagged
  // Measure each frame's flicker to the previous one (a warp of the previous frame into
  // it, for the report): off where no report is read, so that it costs nothing there.
  bool measure_flicker = true;
  FlickerOptions flicker;
  void Check() const;
};

class TemporalSequence {
 public:
  explicit TemporalSequence(const TemporalOptions& options);

  // Fills view->preferred_sources with the previous frame's sources.
  void PrepareView(TargetView* view) const;
  // Blends (when asked), measures flicker and coverage, remembers the frame; the returned
  // row has everything but the timing filled. `result` must come from rendering `view`.
  FrameReportRow Finish(const TargetView& view, RenderResult* result);
  void Reset() { has_previous_ = false; }
  // Takes `result` (rendered for `view`) as the previous frame as it is: no blend, no
  // measurement.
  void Remember(const TargetView& view, const RenderResult& result);

 private:
  TemporalOptions options_;
  bool has_previous_ = false;
  PinholeCamera previous_camera_;
  Image previous_color_, previous_depth_, previous_coverage_;
  std::vector<int> previous_sources_;
};

// Fraction of pixels with a contribution.
double CoverageFraction(const Image& coverage);

}  // namespace fvs
