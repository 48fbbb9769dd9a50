#include "fvs/controllers/evaluation_report.h"

#include <cstdio>

#include "colmap_ext/image_io.h"
#include "fvs/eval/contact_sheet.h"
#include "fvs/eval/plot.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/shard.h"

namespace fvs {

void WriteEvaluationReports(const EvaluationOptions& o, const EvaluationResult& result,
                            const ContactSheetViews& sheet, size_t num_configs) {
  eval::ReportHeader context;
  context.title = "view_synthesis_eval: " + result.scene_name;
  context.machine = result.machine;
  context.workspace = o.workspace_path;
  context.notes = result.notes;
  eval::WriteResultsCsv(o.output_path + "/results.csv", result.results);
  eval::WriteSummaryCsv(o.output_path + "/summary.csv", result.summary);
  eval::WriteMarkdownReport(o.output_path + "/results.md", context, result.results,
                            result.summary);
  WriteFileAtomic(o.output_path + "/machine.txt",
                  [&](std::ostream& out) { out << context.machine << "\n"; });
  if (o.thumbnail_width > 0) {
    const Shard shard = Shard::Parse(o.shard);
    colmap::WriteImage(
        o.output_path + "/contact_sheet.png",
        eval::MakeContactSheet(result.scene_name + ": " + sheet.config.Label() +
                                   (shard.IsAll() ? "" : ", shard " + shard.ToString()),
                               sheet.results, sheet.thumbnails));
  }
  if (num_configs > 1) {
    eval::PlotOptions plot;
    plot.title = "Quality against run time: " + result.scene_name;
    plot.footer = context.machine;
    plot.time = eval::ParseTimeMeasure(o.time);
    try {
      colmap::WriteImage(o.output_path + "/error_vs_time.png",
                         eval::PlotErrorAgainstTime(result.summary, plot));
    } catch (const Error& e) {
      std::fprintf(stderr, "WARNING: no plot: %s\n", e.what());
    }
  }
}

void PrintEvaluationSummary(const EvaluationOptions& o, const EvaluationResult& result) {
  using eval::FormatNumber;
  std::printf("%s\n", result.machine.c_str());
  for (const std::string& n : result.notes) std::printf("%s\n", n.c_str());
  std::printf("%-26s %5s %6s %8s %8s %8s %9s %9s %9s %7s %6s\n", "configuration", "views",
              "failed", "PSNR", "SSIM", "LPIPS", "PSNR_cov", "s/view", "CPU_s", "K used",
              "Pareto");
  for (const eval::ConfigSummary& s : result.summary) {
    std::printf("%-26s %5d %6d %8s %8s %8s %9s %9s %9s %7s %6s\n",
                s.config.Label().c_str(), s.views_ok, s.views_failed,
                FormatNumber(s.psnr, 2).c_str(), FormatNumber(s.ssim, 4).c_str(),
                FormatNumber(s.lpips, 4).c_str(), FormatNumber(s.psnr_covered, 2).c_str(),
                FormatNumber(s.seconds, 3).c_str(),
                FormatNumber(s.cpu_seconds, 3).c_str(),
                FormatNumber(s.sources_used, 1).c_str(), s.pareto ? "yes" : "");
  }
  std::printf("wrote %s/results.csv, summary.csv, results.md\n", o.output_path.c_str());
  for (const eval::EvalTarget& t : result.targets) {
    if (t.skipped) std::printf("skipped %s: %s\n", t.name.c_str(), t.error.c_str());
  }
}

void RequireNoFailedViews(const EvaluationOptions& o, const EvaluationResult& result) {
  int failed = 0;
  const eval::ViewResult* first_failure = nullptr;
  for (const eval::ViewResult& r : result.results) {
    if (r.failed()) {
      ++failed;
      if (!first_failure) first_failure = &r;
    }
  }
  if (failed > 0) {
    throw Error(o.output_path + "/results.csv",
                std::to_string(failed) + " of " + std::to_string(result.results.size()) +
                    " view evaluations failed (first: " + first_failure->target + ": " +
                    first_failure->error + "); the others are reported");
  }
}

}  // namespace fvs
