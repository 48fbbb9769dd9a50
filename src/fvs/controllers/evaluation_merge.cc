#include "fvs/controllers/evaluation_merge.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <vector>

#include "colmap_ext/image_io.h"
#include "fvs/eval/contact_sheet.h"
#include "fvs/eval/plot.h"
#include "fvs/eval/report.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;
using eval::ViewResult;

std::vector<std::string> InputFolders(const std::string& input_paths) {
  std::vector<std::string> inputs;
  for (const std::string& p : SplitString(input_paths, ",")) {
    if (!TrimString(p).empty()) inputs.push_back(TrimString(p));
  }
  return inputs;
}

struct Shards {
  std::vector<ViewResult> results;
  std::set<std::string> machines;
  std::vector<Image> sheets;
};

Shards ReadShards(const std::vector<std::string>& inputs) {
  Shards shards;
  std::map<std::string, std::string> seen;  // config + target -> shard folder
  for (const std::string& input : inputs) {
    const std::string csv = input + "/results.csv";
    Require(fs::is_regular_file(csv), input,
            "no results.csv (not an output folder of view_synthesis_eval?)");
    for (ViewResult& r : eval::ReadResultsCsv(csv)) {
      const std::string key = r.scene + "|" + r.config.Label() + "|" + r.target;
      const auto [it, fresh] = seen.emplace(key, input);
      Require(fresh, csv,
              "'" + r.target + "' (" + r.config.Label() + ") is also in " + it->second +
                  ": overlapping shards");
      shards.results.push_back(std::move(r));
    }
    if (fs::is_regular_file(input + "/machine.txt")) {
      shards.machines.insert(TrimString(ReadFileToString(input + "/machine.txt")));
    }
    if (fs::is_regular_file(input + "/contact_sheet.png")) {
      shards.sheets.push_back(colmap::ReadImage(input + "/contact_sheet.png", 3));
    }
  }
  return shards;
}

// Configurations in order of first appearance, targets by name within each.
void SortRows(std::vector<ViewResult>* results) {
  std::map<std::string, int> config_order;
  for (const ViewResult& r : *results) {
    config_order.emplace(r.config.Label(), static_cast<int>(config_order.size()));
  }
  std::stable_sort(results->begin(), results->end(),
                   [&](const ViewResult& a, const ViewResult& b) {
                     const int ca = config_order[a.config.Label()];
                     const int cb = config_order[b.config.Label()];
                     return ca != cb ? ca < cb : a.target < b.target;
                   });
}

void WritePlot(const std::string& output_path, const Shards& shards,
               const std::vector<eval::ConfigSummary>& summary,
               const std::string& machine, eval::TimeMeasure time) {
  eval::PlotOptions plot;
  std::set<std::string> scenes;
  for (const ViewResult& r : shards.results) scenes.insert(r.scene);
  if (scenes.size() == 1) plot.title += ": " + *scenes.begin();
  plot.footer = machine;
  plot.time = time;
  try {
    colmap::WriteImage(output_path + "/error_vs_time.png",
                       eval::PlotErrorAgainstTime(summary, plot));
  } catch (const Error& e) {
    std::fprintf(stderr, "WARNING: no plot: %s\n", e.what());
  }
}

void WriteMerged(const MergeEvaluationsOptions& o, size_t num_inputs,
                 const Shards& shards) {
  const eval::TimeMeasure time = eval::ParseTimeMeasure(o.time);
  std::error_code ec;
  fs::create_directories(o.output_path, ec);
  Require(!ec, o.output_path, "cannot create the output folder: " + ec.message());
  const std::vector<eval::ConfigSummary> summary = eval::Summarize(shards.results, time);
  eval::ReportHeader context;
  context.title = "view_synthesis_eval (merged from " + std::to_string(num_inputs) +
                  " shard folders)";
  for (const std::string& m : shards.machines) {
    context.machine += (context.machine.empty() ? "" : "; ") + m;
  }
  context.notes.push_back("merged from: " + o.input_paths);
  if (shards.machines.size() > 1) {
    context.notes.push_back(
        "the shards ran on different machines: compare seconds "
        "per view only within one machine");
  }
  eval::WriteResultsCsv(o.output_path + "/results.csv", shards.results);
  eval::WriteSummaryCsv(o.output_path + "/summary.csv", summary);
  eval::WriteMarkdownReport(o.output_path + "/results.md", context, shards.results,
                            summary);
  WriteFileAtomic(o.output_path + "/machine.txt",
                  [&](std::ostream& out) { out << context.machine << "\n"; });
  if (!shards.sheets.empty()) {
    colmap::WriteImage(o.output_path + "/contact_sheet.png",
                       eval::StackVertically(shards.sheets));
  }
  if (summary.size() > 1)
    WritePlot(o.output_path, shards, summary, context.machine, time);
}

}  // namespace

void MergeEvaluationsOptions::Check() const {
  eval::ParseTimeMeasure(time);
  Require(!InputFolders(input_paths).empty(), "--input_paths", "no folder given");
}

MergeEvaluationsResult MergeEvaluations(const MergeEvaluationsOptions& o) {
  o.Check();
  const std::vector<std::string> inputs = InputFolders(o.input_paths);
  Shards shards = ReadShards(inputs);
  SortRows(&shards.results);
  WriteMerged(o, inputs.size(), shards);
  MergeEvaluationsResult result;
  result.num_inputs = static_cast<int>(inputs.size());
  result.num_rows = static_cast<int>(shards.results.size());
  for (const ViewResult& r : shards.results) result.num_failed += r.failed() ? 1 : 0;
  return result;
}

}  // namespace fvs
