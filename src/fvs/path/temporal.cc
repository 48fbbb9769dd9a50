#include "fvs/path/temporal.h"

#include <algorithm>
#include <cmath>

#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {

void TemporalOptions::Check() const {
  Require(std::isfinite(temporal_blend) && temporal_blend >= 0 && temporal_blend < 1,
          "--temporal_blend", "must be in [0, 1)");
  Require(std::isfinite(coverage_threshold) && coverage_threshold >= 0 &&
              coverage_threshold <= 1,
          "--flag_coverage", "must be in [0, 1]");
  flicker.Check();
}

double CoverageFraction(const Image& coverage) {
  if (coverage.data.empty()) return 0;
  double sum = 0;
  for (float c : coverage.data) sum += c > 0 ? 1.0 : 0.0;
  return sum / coverage.data.size();
}

TemporalSequence::TemporalSequence(const TemporalOptions& options) : options_(options) {
  options_.Check();
}

void TemporalSequence::PrepareView(TargetView* view) const {
  if (has_previous_ && options_.use_preferred_sources) {
    view->preferred_sources = previous_sources_;
  }
}

FrameReportRow TemporalSequence::Finish(const TargetView& view, RenderResult* result) {
  Timer timer;
  FrameReportRow row;
  row.frame = view.name;
  const bool sized = result->color.width == view.camera.width &&
                     result->color.height == view.camera.height &&
                     result->depth.width == view.camera.width &&
                     result->depth.height == view.camera.height;
  const bool chain = has_previous_ && sized &&
                     previous_camera_.width == view.camera.width &&
                     previous_camera_.height == view.camera.height;
  if (chain && options_.temporal_blend > 0) {
    const WarpedFrame warped =
        WarpFrame(previous_color_, previous_depth_, previous_camera_, result->depth,
                  view.camera, options_.flicker, &previous_coverage_);
    const float a = static_cast<float>(options_.temporal_blend);
    for (size_t i = 0; i < warped.valid.data.size(); ++i) {
      if (!(warped.valid.data[i] > 0) || !(result->coverage.data[i] > 0)) continue;
      for (int c = 0; c < 3; ++c) {
        float& v = result->color.data[3 * i + c];
        v = std::clamp((1 - a) * v + a * warped.color.data[3 * i + c], 0.f, 1.f);
      }
    }
  }
  row.coverage = CoverageFraction(result->coverage);
  row.flagged = row.coverage < options_.coverage_threshold;
  std::vector<int> sources;
  for (const SourceScore& s : result->sources) {
    sources.push_back(s.view_index);
    if (!row.sources.empty()) row.sources += ";";
    row.sources += std::to_string(s.view_index);
  }
  if (chain) {
    row.source_changes = 0;
    for (int s : sources) {
      row.source_changes += std::find(previous_sources_.begin(), previous_sources_.end(),
                                      s) == previous_sources_.end();
    }
  }
  if (chain && options_.measure_flicker) {
    const FlickerPair pair = MeasureFlicker(
        previous_color_, previous_depth_, previous_camera_, result->color, result->depth,
        view.camera, options_.flicker, &previous_coverage_, &result->coverage);
    row.flicker = pair.mean_abs;
    row.covisible = pair.covisible_fraction;
  }
  Remember(view, *result);
  row.temporal_seconds = timer.Seconds();
  return row;
}

void TemporalSequence::Remember(const TargetView& view, const RenderResult& result) {
  const int n = view.camera.width * view.camera.height;
  has_previous_ = static_cast<int>(result.depth.data.size()) == n &&
                  static_cast<int>(result.coverage.data.size()) == n &&
                  static_cast<int>(result.color.data.size()) == 3 * n;
  if (!has_previous_) return;
  previous_camera_ = view.camera;
  previous_color_ = result.color;
  previous_depth_ = result.depth;
  previous_coverage_ = result.coverage;
  previous_sources_.clear();
  for (const SourceScore& s : result.sources) previous_sources_.push_back(s.view_index);
}

}  // namespace fvs
