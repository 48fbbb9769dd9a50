// colmap view_synthesis_eval_merge --input_paths O0,O1,... --output_path O
// Merges the output folders of view_synthesis_eval shards (--shard i/n) into one report:
// results.csv rows concatenated (configurations in order of first appearance, targets by
// name), summary.csv / results.md recomputed from them, the shards' contact sheets
// stacked, and the error-against-time plot for more than one configuration. A target
// evaluated twice with the same configuration (overlapping shards) is an error.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "colmap_ext/image_io.h"
#include "fvs/eval/contact_sheet.h"
#include "fvs/eval/plot.h"
#include "fvs/eval/report.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/option_manager.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

using namespace eval;  // NOLINT: the command is a thin layer over fvs::eval
namespace fs = std::filesystem;

int RunViewSynthesisEvalMerge(int argc, char** argv) {
  std::string input_paths, output_path, time = "wall";
  OptionManager options("view_synthesis_eval_merge",
                        "Merge the output folders of view_synthesis_eval shards into one "
                        "report.");
  options.AddRequired("input_paths", &input_paths,
                      "comma-separated output folders of the shards");
  options.AddRequired("output_path", &output_path, "folder for the merged report");
  options.AddDefault("time", &time, "time of the Pareto front and the plot: wall or cpu");
  if (!options.Parse(argc, argv)) return 0;
  const TimeMeasure time_measure = ParseTimeMeasure(time);

  std::vector<std::string> inputs;
  for (const std::string& p : SplitString(input_paths, ",")) {
    if (!TrimString(p).empty()) inputs.push_back(TrimString(p));
  }
  Require(!inputs.empty(), "--input_paths", "no folder given");

  // Read everything first: a bad shard leaves nothing half-merged.
  std::vector<ViewResult> results;
  std::map<std::string, std::string> seen;  // config + target -> shard folder
  std::set<std::string> machines;
  std::vector<Image> sheets;
  for (const std::string& input : inputs) {
    const std::string csv = input + "/results.csv";
    Require(fs::is_regular_file(csv), input,
            "no results.csv (not an output folder of view_synthesis_eval?)");
    for (ViewResult& r : ReadResultsCsv(csv)) {
      const std::string key = r.scene + "|" + r.config.Label() + "|" + r.target;
      const auto [it, fresh] = seen.emplace(key, input);
      Require(fresh, csv,
              "'" + r.target + "' (" + r.config.Label() + ") is also in " + it->second +
                  ": overlapping shards");
      results.push_back(std::move(r));
    }
    if (fs::is_regular_file(input + "/machine.txt")) {
      machines.insert(TrimString(ReadFileToString(input + "/machine.txt")));
    }
    if (fs::is_regular_file(input + "/contact_sheet.png")) {
      sheets.push_back(colmap::ReadImage(input + "/contact_sheet.png", 3));
    }
  }
  // Configurations in order of first appearance, targets by name within each.
  std::map<std::string, int> config_order;
  for (const ViewResult& r : results) {
    config_order.emplace(r.config.Label(), static_cast<int>(config_order.size()));
  }
  std::stable_sort(results.begin(), results.end(),
                   [&](const ViewResult& a, const ViewResult& b) {
                     const int ca = config_order[a.config.Label()];
                     const int cb = config_order[b.config.Label()];
                     return ca != cb ? ca < cb : a.target < b.target;
                   });

  std::error_code ec;
  fs::create_directories(output_path, ec);
  Require(!ec, output_path, "cannot create the output folder: " + ec.message());
  const std::vector<ConfigSummary> summary = Summarize(results, time_measure);
  ReportContext context;
  context.title = "view_synthesis_eval (merged from " + std::to_string(inputs.size()) +
                  " shard folders)";
  for (const std::string& m : machines) {
    context.machine += (context.machine.empty() ? "" : "; ") + m;
  }
  context.notes.push_back("merged from: " + input_paths);
  if (machines.size() > 1) {
    context.notes.push_back(
        "the shards ran on different machines: compare seconds "
        "per view only within one machine");
  }
  WriteResultsCsv(output_path + "/results.csv", results);
  WriteSummaryCsv(output_path + "/summary.csv", summary);
  WriteMarkdownReport(output_path + "/results.md", context, results, summary);
  WriteFileAtomic(output_path + "/machine.txt",
                  [&](std::ostream& out) { out << context.machine << "\n"; });
  if (!sheets.empty()) {
    colmap::WriteImage(output_path + "/contact_sheet.png", StackVertically(sheets));
  }
  if (summary.size() > 1) {
    PlotOptions plot;
    std::set<std::string> scenes;
    for (const ViewResult& r : results) scenes.insert(r.scene);
    if (scenes.size() == 1) plot.title += ": " + *scenes.begin();
    plot.footer = context.machine;
    plot.time = time_measure;
    try {
      colmap::WriteImage(output_path + "/error_vs_time.png",
                         PlotErrorAgainstTime(summary, plot));
    } catch (const Error& e) {
      std::fprintf(stderr, "WARNING: no plot: %s\n", e.what());
    }
  }
  int failed = 0;
  for (const ViewResult& r : results) failed += r.failed() ? 1 : 0;
  std::printf("merged %zu rows (%d failed) from %zu folders into %s\n", results.size(),
              failed, inputs.size(), output_path.c_str());
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_eval_merge",
                     "merge view_synthesis_eval shard folders into one report",
                     RunViewSynthesisEvalMerge);

}  // namespace fvs
