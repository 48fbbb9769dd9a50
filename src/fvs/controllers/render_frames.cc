#include "fvs/controllers/render_frames.h"

#include "colmap_ext/image_io.h"
#include "fvs/controllers/ground_truth.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

// "3;0;5" (a report row's sources) -> {3, 0, 5}; what does not parse is left out.
std::vector<int> ParseSources(const std::string& text) {
  std::vector<int> out;
  for (const std::string& s : SplitString(text, ";")) {
    try {
      if (!s.empty()) out.push_back(std::stoi(s));
    } catch (const std::exception&) {
    }
  }
  return out;
}

class FrameLoop {
 public:
  FrameLoop(const Scene& scene, Method* method, const std::vector<RenderFrame>& frames,
            const RenderFramesOptions& options)
      : scene_(scene),
        method_(method),
        frames_(frames),
        options_(options),
        sequence_(options.temporal) {}

  // Checked when the frame is reached, so that the frames before a bad camera are kept.
  TargetView MakeView(size_t k) const {
    const TargetCamera& t = frames_[k].target;
    TargetView view;
    view.name = t.name;
    view.camera = scene_.ToSceneCamera(t.camera);
    Require(view.camera.IsValid(), t.name, "invalid target camera");
    if (options_.holdout && !t.image_name.empty()) {
      const int index = scene_.FindView(t.image_name);
      if (index >= 0) view.exclude_views.push_back(index);
    }
    return view;
  }

  // The frame before a missing one was resumed from disk: render it again (with the
  // sources its report row names preferred) and continue the chain from its colour on
  // disk, so that resuming does not restart the stable sources, blend and flicker.
  void RestoreChain(size_t k) {
    TargetView view = MakeView(k);
    const auto it = options_.earlier.find(frames_[k].target.name);
    if (it != options_.earlier.end()) {
      view.preferred_sources = ParseSources(it->second.sources);
    }
    RenderResult result = method_->Render(scene_, view);
    try {
      result.color = colmap::ReadImage(
          JoinPaths(options_.output_path, frames_[k].target.name + ".png"));
    } catch (const Error&) {
      return;  // unreadable after all: the chain restarts
    }
    sequence_.Remember(view, result);
  }

  void Resume(size_t k) {
    sequence_.Reset();
    const std::string& name = frames_[k].target.name;
    const auto it = options_.earlier.find(name);
    FrameReportRow row = it != options_.earlier.end() ? it->second : FrameReportRow();
    row.frame = name;
    row.status = "resumed";
    result_.report.push_back(row);
  }

  void Render(size_t k) {
    const std::string& name = frames_[k].target.name;
    if (k > 0 && frames_[k - 1].done) RestoreChain(k - 1);
    TargetView view = MakeView(k);
    sequence_.PrepareView(&view);
    Timer frame_timer;
    RenderResult result = method_->Render(scene_, view);
    FrameReportRow row = sequence_.Finish(view, &result);
    WriteRenderOutputs(options_.output_path, name, options_.method, scene_, result,
                       options_.output);
    row.seconds = frame_timer.Seconds();
    row.psnr = FramePsnr(options_.ground_truth_path, name, result.color);
    result_.report.push_back(row);
    result_.rendered.push_back({k, result.timings, row.coverage});
    // Every frame, so that a killed run keeps the rows of what it finished.
    WriteReport();
  }

  void WriteReport() const {
    if (options_.report_stem.empty()) return;
    WriteFrameReport(
        options_.report_stem, result_.report,
        SummariseFrameReport(result_.report, options_.temporal.coverage_threshold),
        options_.report_extra_json);
  }

  RenderFramesResult Finish() {
    result_.summary =
        SummariseFrameReport(result_.report, options_.temporal.coverage_threshold);
    WriteReport();
    return std::move(result_);
  }

 private:
  const Scene& scene_;
  Method* method_;
  const std::vector<RenderFrame>& frames_;
  const RenderFramesOptions& options_;
  TemporalSequence sequence_;
  RenderFramesResult result_;
};

}  // namespace

void RenderFramesOptions::Check() const {
  Require(!output_path.empty(), "RenderFrames", "no output folder given");
  temporal.Check();
}

RenderFramesResult RenderFrames(const Scene& scene, Method* method,
                                const std::vector<RenderFrame>& frames,
                                const RenderFramesOptions& options,
                                const RenderFramesCallbacks& callbacks) {
  options.Check();
  FrameLoop loop(scene, method, frames, options);
  for (size_t k = 0; k < frames.size(); ++k) {
    if (callbacks.cancelled && callbacks.cancelled()) break;
    if (frames[k].done) {
      loop.Resume(k);
      continue;
    }
    if (callbacks.before_frame) callbacks.before_frame(k);
    loop.Render(k);
    if (callbacks.after_frame) callbacks.after_frame(k);
  }
  return loop.Finish();
}

}  // namespace fvs
