// Evaluating a prepared workspace as one call: what `colmap view_synthesis_eval` runs.
// The protocol's targets (eval/protocol.h: holdout, leave_one_out, subsequence, indices)
// are rendered at the photos' size with one configuration (method, K, scale, precision)
// or every configuration of a sweep (eval/sweep.h), scored against the photos (PSNR,
// SSIM, LPIPS when its weights are found) beside their run time, and written to
// <output_path>/results.csv, summary.csv, results.md, machine.txt, contact_sheet.png and,
// for more than one configuration, error_vs_time.png. Each view's result is kept in
// <output_path>/views/ as soon as it is done (eval/view_journal.h): a killed evaluation,
// run again with the same settings, renders only the views it had not finished.
//
// Bad views are reported in their rows and the others still evaluated
// (RequireNoFailedViews turns them into an error afterwards). A held-out image SfM did
// not register is listed as skipped (status "skipped", the reason in "error"), which is
// not a failure.
#pragma once

#include <string>
#include <vector>

#include "fvs/eval/evaluate.h"
#include "fvs/eval/protocol.h"
#include "fvs/eval/report.h"
#include "fvs/eval/sweep.h"
#include "fvs/render/method.h"

namespace fvs {

struct EvaluationOptions {
  std::string workspace_path;
  std::string output_path;
  eval::ProtocolOptions protocol;
  eval::EvalConfig config;  // the one configuration, or the contact sheet's of a sweep
  bool sweep = false;
  eval::SweepOptions sweep_options;
  std::string shard;       // "i/n": every n-th target from i (view_synthesis_eval_merge)
  std::string lpips_path;  // LPIPS weights; empty: $FVS_LPIPS_PATH (eval/lpips.h)
  std::string time = "wall";  // of the Pareto front and the plot: wall or cpu
  std::string scene_name;     // in the reports; empty: the workspace folder's name
  int thumbnail_width = 320;  // contact sheet tiles; 0: no contact sheet
  bool write_images = false;  // every render to <output_path>/renders/<configuration>/
  bool overwrite =
      false;  // evaluate every view again (else <output_path>/views/ resumes)
  // The renderer's engine (sources, tolerances, holes, device, tiles, threads). Its
  // num_sources, model_path and precision are not used: `config` (or the sweep) has them.
  RenderOptions render;

  // Throws fvs::Error with one line naming the option that is wrong.
  void Check() const;
};

struct EvaluationResult {
  std::string scene_name;
  std::string machine;
  std::vector<std::string> notes;         // protocol, sweep, LPIPS, photos left out
  std::vector<eval::EvalTarget> targets;  // of this shard, skipped ones included
  std::vector<eval::ViewResult> results;  // every configuration's rows
  std::vector<eval::ConfigSummary> summary;
};

// Runs the whole evaluation and writes its reports. Everything that can fail without the
// scene (options, methods, weights) fails before it is loaded; a bad view does not throw.
// Warnings (LPIPS weights that do not load, photos left out, no plot) go to stderr.
EvaluationResult RunEvaluation(const EvaluationOptions& options);

// The machine, the notes and the table of configurations, on stdout, and the targets
// that were skipped.
void PrintEvaluationSummary(const EvaluationOptions& options,
                            const EvaluationResult& result);

// Throws fvs::Error naming <output_path>/results.csv when any view failed: how many, and
// the first one's error.
void RequireNoFailedViews(const EvaluationOptions& options,
                          const EvaluationResult& result);

}  // namespace fvs
