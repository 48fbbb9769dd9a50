// Rendering a set of targets of a prepared workspace as one call: what `colmap
// view_synthesis` runs. The targets are the poses of an images.txt, a nerfstudio camera
// path, an orbit or views between the registered cameras; every one is rendered into
// <output_path>/<name>.png (plus the extras of RenderOutputOptions), optionally encoded
// into a video.
//
// Resume: a target whose PNG already exists with the right size is skipped unless
// `overwrite`, so an interrupted render resumes at the first missing frame. Frames are
// resumed only when <output_path>/render_settings.json matches this run: the settings and
// the content hashes of the weights, of the workspace (sparse model, mesh, photos) and of
// the target file (render_settings.h), so weights retrained to the same path never reuse
// old frames. <output_path>/frame_report.{csv,json} hold per frame the coverage (flagged
// under temporal.coverage_threshold), the sources, the flicker to the previous frame and
// the PSNR against the ground truth; the temporal chain goes on across resumed frames
// (render_frames.h).
#pragma once

#include <string>
#include <vector>

#include "fvs/controllers/render_frames.h"
#include "fvs/path/temporal.h"
#include "fvs/path/video.h"
#include "fvs/render/method.h"
#include "fvs/render/render_output.h"

namespace fvs {

struct RenderTargetsOptions {
  std::string workspace_path;
  std::string output_path;
  // Exactly one of these four says what the targets are.
  std::string target_images;  // COLMAP images.txt (cameras.txt beside it)
  std::string camera_path;    // nerfstudio camera_path.json
  int orbit = 0;              // N views on a circle around the scene centre
  int interpolate = 0;        // N views between consecutive registered cameras
  std::string method = "ulr";
  int width = 0;  // 0: the target camera's
  int height = 0;
  double scale = 1.0;
  bool holdout = false;
  bool disk_feature_cache = false;  // encoded features under W/fvs/features
  std::string shard;                // "i/n": every n-th target from i (batch array jobs)
  // scene_model_dir and, with disk_feature_cache, feature_cache_dir are set from the
  // workspace by RunRenderTargets.
  RenderOptions render;
  RenderOutputOptions output;
  std::string video;  // also encode the frames into this mp4; empty: none
  double fps = 0;     // 0: the camera path's "fps", else 30
  bool overwrite = false;
  // Temporally stable sources: source_hysteresis 0.1 (unless set) and stable order.
  bool stable_sources = false;
  TemporalOptions temporal;
  std::string ground_truth_path;  // folder of ground-truth frames named as the output

  // Throws fvs::Error with one line naming the option that is wrong.
  void Check() const;
};

struct RenderTargetsResult {
  // A shard of a path shorter than its index: nothing rendered, nothing written.
  bool shard_empty = false;
  int num_views = 0;  // of the scene
  double scene_load_seconds = 0;
  int num_depths_computed = 0;
  std::vector<std::string> target_names;  // every target of this run (of its shard)
  RenderFramesResult frames;
  bool has_video = false;
  VideoResult video;
};

// Runs the whole render: checks the options and every input (method, photos, ground
// truth) before the output folder is touched, loads the scene, renders what is missing,
// writes the report and encodes the video. Prints what it decides (resuming, an empty
// shard) and a progress bar on stderr. Throws fvs::Error with one line for bad input.
RenderTargetsResult RunRenderTargets(RenderTargetsOptions options);

// The per-target timing table, the coverage, flicker and PSNR summary and the video's
// note, on stdout.
void PrintRenderTargetsSummary(const RenderTargetsOptions& options,
                               const RenderTargetsResult& result);

}  // namespace fvs
