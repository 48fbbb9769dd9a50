// The frame loop of a render, shared by `colmap view_synthesis` (RunRenderTargets) and
// the GUI's path render: every target in order through a TemporalSequence (stable
// sources, temporal blend, flicker), its outputs (render_output.h) and, when a report is
// asked for, the frame report (path/frame_report.h) rewritten after every frame, so that
// a killed run keeps the rows of what it finished.
//
// A frame marked done (its PNG from an earlier run is kept) gets a "resumed" row with
// what the earlier report said of it. The temporal chain goes on across resumed frames:
// the last one before a missing frame is rendered again, with the sources its earlier
// row names preferred, and its colour taken from disk.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "fvs/path/frame_report.h"
#include "fvs/path/temporal.h"
#include "fvs/render/method.h"
#include "fvs/render/render_output.h"
#include "fvs/render/targets.h"

namespace fvs {

class Scene;

struct RenderFrame {
  TargetCamera target;  // camera at the output size, in the scene's input frame
  bool done = false;    // resumed: <output_path>/<name>.png is kept as it is
};

struct RenderFramesOptions {
  std::string output_path;  // <output_path>/<name>.png and the extras of `output`
  std::string method;       // its name, for the outputs that record it
  RenderOutputOptions output;
  TemporalOptions temporal;
  // A target named like a registered image (TargetCamera::image_name) does not use it.
  bool holdout = false;
  std::string ground_truth_path;  // PSNR of every frame with a ground truth; empty: none
  std::string report_stem;        // <stem>.csv and .json; empty: no report written
  std::string report_extra_json;  // merged into the report's JSON summary
  // The rows of an earlier report by frame name: resumed frames keep theirs.
  std::map<std::string, FrameReportRow> earlier;

  // Throws fvs::Error with one line: no output folder, or temporal options out of range.
  void Check() const;
};

struct RenderFramesCallbacks {
  // Asked before every frame: true stops the loop (the frames so far are kept).
  std::function<bool()> cancelled;
  // Before frame `index` is rendered (not called for resumed frames).
  std::function<void(size_t index)> before_frame;
  // After frame `index` was rendered and written.
  std::function<void(size_t index)> after_frame;
};

struct RenderedFrame {
  size_t index = 0;  // into the frames given
  RenderTimings timings;
  double coverage = 0;
};

struct RenderFramesResult {
  std::vector<FrameReportRow> report;   // one row per frame reached, in order
  std::vector<RenderedFrame> rendered;  // the frames rendered (not resumed)
  FrameReportSummary summary;
};

// Renders `frames` of `scene` with `method` in order. Throws fvs::Error for bad options
// (before any frame), an invalid target camera or a failed render or write (the frames
// before it are on disk).
RenderFramesResult RenderFrames(const Scene& scene, Method* method,
                                const std::vector<RenderFrame>& frames,
                                const RenderFramesOptions& options,
                                const RenderFramesCallbacks& callbacks = {});

}  // namespace fvs
