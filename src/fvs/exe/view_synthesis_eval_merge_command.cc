// colmap view_synthesis_eval_merge --input_paths O0,O1,... --output_path O
// Merges the output folders of view_synthesis_eval shards (--shard i/n) into one report:
// MergeEvaluations (controllers/evaluation_merge.h) does the work and states how rows are
// ordered. A target evaluated twice with the same configuration (overlapping shards) is
// an error.
#include <cstdio>
#include <string>

#include "fvs/controllers/evaluation_merge.h"
#include "fvs/exe/command_registry.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunViewSynthesisEvalMerge(int argc, char** argv) {
  MergeEvaluationsOptions o;
  OptionManager options("view_synthesis_eval_merge",
                        "Merge the output folders of view_synthesis_eval shards into one "
                        "report.");
  options.AddRequired("input_paths", &o.input_paths,
                      "comma-separated output folders of the shards");
  options.AddRequired("output_path", &o.output_path, "folder for the merged report");
  options.AddDefault("time", &o.time,
                     "time of the Pareto front and the plot: wall or cpu");
  if (!options.Parse(argc, argv)) return 0;
  const MergeEvaluationsResult merged = MergeEvaluations(o);
  std::printf("merged %d rows (%d failed) from %d folders into %s\n", merged.num_rows,
              merged.num_failed, merged.num_inputs, o.output_path.c_str());
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_eval_merge",
                     "merge view_synthesis_eval shard folders into one report",
                     RunViewSynthesisEvalMerge);

}  // namespace fvs
