// colmap view_synthesis_stability [--methods nearest,ulr] [--model_path W] [--output_path
// O] Runs the renderer's numerical stability suite (fvs/eval/stability.h) and prints, per
// case and method, NaN/Inf counts, the maximum colour deviation when the whole scene is
// moved 10 km from the origin, and the time. Exit status 1 when any case fails (a NaN or
// Inf, an exception, or a deviation above 1/255). --output_path also writes
// stability.csv and stability.md there.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "fvs/eval/report.h"
#include "fvs/eval/stability.h"
#include "fvs/exe/command_registry.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/option_manager.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

using namespace eval;  // NOLINT: the command is a thin layer over fvs::eval

// Prints the table of `results` and, with an output folder, writes it as stability.csv
// and stability.md there. Returns how many cases failed.
int ReportStabilityResults(const std::vector<StabilityResult>& results,
                           const StabilityOptions& o, const std::string& output_path) {
  const std::string machine = DescribeMachine();
  char header[256];
  std::snprintf(header, sizeof(header), "%-15s %-10s %7s %7s %8s %11s %9s %8s %s", "case",
                "method", "NaN", "Inf", "covered", "max_dev_far", "px>1/255", "time_s",
                "status");
  std::printf("%s\nfar copy: %.0f m from the origin; %dx%d\n%s\n", machine.c_str(),
              o.far_offset_m, o.width, o.height, header);
  std::string csv =
      "case,method,nan,inf,covered,max_deviation_far,pixels_deviating,seconds,status,"
      "error\n";
  std::string md =
      "| case | method | NaN | Inf | covered | max deviation at " +
      FormatNumber(o.far_offset_m / 1000, 0) +
      " km | pixels > 1/255 | s | status |\n| --- | --- | ---: | ---: | ---: "
      "| ---: | ---: | ---: | --- |\n";
  int failed = 0;
  for (const StabilityResult& r : results) {
    const std::string status = r.ok() ? "ok" : (r.error.empty() ? "FAIL" : "ERROR");
    failed += r.ok() ? 0 : 1;
    std::printf("%-15s %-10s %7ld %7ld %7.1f%% %11.2e %9ld %8.3f %s%s\n",
                r.case_name.c_str(), r.method.c_str(), r.nan_count, r.inf_count,
                100 * r.covered, r.max_deviation, r.pixels_deviating, r.seconds,
                status.c_str(), r.error.empty() ? "" : (": " + r.error).c_str());
    char line[512];
    std::snprintf(line, sizeof(line), "%s,%s,%ld,%ld,%.4f,%.3e,%ld,%.4f,%s,",
                  r.case_name.c_str(), r.method.c_str(), r.nan_count, r.inf_count,
                  r.covered, r.max_deviation, r.pixels_deviating, r.seconds,
                  status.c_str());
    std::string error = r.error;
    for (char& c : error) {
      if (c == ',' || c == '\n' || c == '"') c = ' ';
    }
    csv += line + error + "\n";
    std::snprintf(
        line, sizeof(line), "| %s | %s | %ld | %ld | %.1f%% | %.2e | %ld | %.3f | %s |\n",
        r.case_name.c_str(), r.method.c_str(), r.nan_count, r.inf_count, 100 * r.covered,
        r.max_deviation, r.pixels_deviating, r.seconds, status.c_str());
    md += line;
  }
  if (!output_path.empty()) {
    std::filesystem::create_directories(output_path);
    WriteFileAtomic(output_path + "/stability.csv",
                    [&](std::ostream& out) { out << csv; });
    WriteFileAtomic(output_path + "/stability.md", [&](std::ostream& out) {
      out << "# Stability suite\n\n- machine: " << machine << "\n\n" << md;
    });
  }
  return failed;
}

int RunViewSynthesisStability(int argc, char** argv) {
  StabilityOptions o;
  std::string methods = "nearest,ulr";
  std::string output_path;
  OptionManager options("view_synthesis_stability",
                        "The renderer's numerical stability suite: depth 0, depth 1e30, "
                        "target behind every source, a source seen edge-on, a single "
                        "source, K larger than the scene, each also 10 km from the "
                        "origin.");
  options.AddDefault("methods", &methods,
                     "comma-separated methods (network variants need --model_path; "
                     "random weights are fine for this suite)");
  options.AddDefault("model_path", &o.model_path, "network weights");
  options.AddDefault("precision", &o.precision,
                     "network methods: fp32, bf16, or fp16 (CUDA only)");
  options.AddDefault("tile_size", &o.tile_size,
                     "network methods: blend in tiles of at most this size (0: never)");
  options.AddDefault("width", &o.width, "target and source width");
  options.AddDefault("height", &o.height, "target and source height");
  options.AddDefault("far_offset", &o.far_offset_m, "distance of the far copy (m)");
  options.AddDefault("output_path", &output_path,
                     "folder for stability.csv and stability.md (optional)");
  options.AddDefault("num_threads", &o.num_threads, "threads (0: all cores)");
  if (!options.Parse(argc, argv)) return 0;
  Require(o.width >= 16 && o.height >= 16 && o.width <= 4096 && o.height <= 4096,
          "--width/--height", "must be in [16, 4096]");
  Require(o.far_offset_m >= 0 && o.far_offset_m < 1e8, "--far_offset",
          "must be in [0, 1e8)");
  o.methods.clear();
  for (const std::string& m : SplitString(methods, ",")) {
    if (!TrimString(m).empty()) o.methods.push_back(TrimString(m));
  }
  Require(!o.methods.empty(), "--methods", "empty list");
  RenderOptions probe;
  probe.model_path = o.model_path;
  for (const std::string& m : o.methods) CreateMethod(m, probe);  // fail early

  const std::vector<StabilityResult> results = RunStabilitySuite(o);
  const int failed = ReportStabilityResults(results, o, output_path);
  Require(failed == 0, "view_synthesis_stability",
          std::to_string(failed) + " of " + std::to_string(results.size()) +
              " cases failed (see the table above)");
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_stability",
                     "numerical stability suite of the renderer (NaN/Inf, 10 km, time)",
                     RunViewSynthesisStability);

}  // namespace fvs
