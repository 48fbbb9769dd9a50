// The evaluation's outputs, all written atomically:
//   results.csv   one row per (configuration, target view): the numbers or the error
//   summary.csv   one row per configuration: means over the evaluated views, views
//                 failed, and whether the configuration is on the Pareto front of
//                 (seconds per view, PSNR): no other is both faster and better
//   results.md    the same as Markdown tables, with the machine and the protocol
// Numbers that do not exist are written "n/a" (LPIPS without weights), never a guess.
// results.csv is also the input of view_synthesis_eval_merge (shards -> one report).
#pragma once

#include <string>
#include <vector>

#include "fvs/eval/evaluate.h"

namespace fvs::eval {

// Which time the Pareto front and the plot use: wall clock, or CPU time of all threads
// (steadier than wall time on a machine shared with other jobs).
enum class TimeMeasure { kWall, kCpu };
// "wall" or "cpu"; throws fvs::Error("--time", ...) otherwise.
TimeMeasure ParseTimeMeasure(const std::string& name);

struct ConfigSummary {
  EvalConfig config;
  int views_ok = 0;
  int views_failed = 0;
  double psnr = kNotAvailable, ssim = kNotAvailable, lpips = kNotAvailable;
  double psnr_covered = kNotAvailable, ssim_covered = kNotAvailable;  // see ViewResult
  double seconds = kNotAvailable;       // mean wall time per view
  double cpu_seconds = kNotAvailable;   // mean CPU time per view (all threads)
  double sources_used = kNotAvailable;  // mean K actually used
  bool pareto = false;                  // on the front of (time lower, PSNR higher)
  double Time(TimeMeasure measure) const {
    return measure == TimeMeasure::kWall ? seconds : cpu_seconds;
  }
};

// Grouped by configuration in the order they first appear; means over ok views only.
// LPIPS is a mean only when every ok view has it.
std::vector<ConfigSummary> Summarize(const std::vector<ViewResult>& results,
                                     TimeMeasure time = TimeMeasure::kWall);

void WriteResultsCsv(const std::string& path, const std::vector<ViewResult>& results);
// Throws fvs::Error naming the file and line for anything that does not parse.
std::vector<ViewResult> ReadResultsCsv(const std::string& path);
void WriteSummaryCsv(const std::string& path, const std::vector<ConfigSummary>& summary);

struct ReportHeader {
  std::string title = "Evaluation";
  std::string machine;             // DescribeMachine()
  std::string workspace;           // what was evaluated
  std::vector<std::string> notes;  // one bullet each
};
void WriteMarkdownReport(const std::string& path, const ReportHeader& context,
                         const std::vector<ViewResult>& results,
                         const std::vector<ConfigSummary>& summary);

// "12.345" or "n/a".
std::string FormatNumber(double value, int decimals);

}  // namespace fvs::eval
