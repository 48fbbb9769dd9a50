// Merging the output folders of view_synthesis_eval shards (--shard i/n) into one report:
// what `colmap view_synthesis_eval_merge` runs. results.csv rows are concatenated
// (configurations in order of first appearance, targets by name), summary.csv and
// results.md recomputed from them, the shards' contact sheets stacked, and the
// error-against-time plot drawn for more than one configuration.
#pragma once

#include <string>

namespace fvs {

struct MergeEvaluationsOptions {
  std::string input_paths;    // comma-separated output folders of the shards
  std::string output_path;    // folder for the merged report
  std::string time = "wall";  // of the Pareto front and the plot: wall or cpu

  // Throws fvs::Error with one line naming the option that is wrong.
  void Check() const;
};

struct MergeEvaluationsResult {
  int num_inputs = 0;
  int num_rows = 0;
  int num_failed = 0;  // rows of views that failed
};

// Reads every shard first, so that a bad one leaves nothing half-merged: a folder without
// results.csv, or a target evaluated twice with the same configuration (overlapping
// shards), throws fvs::Error with one line naming it. A plot that cannot be drawn is a
// warning on stderr.
MergeEvaluationsResult MergeEvaluations(const MergeEvaluationsOptions& options);

}  // namespace fvs
