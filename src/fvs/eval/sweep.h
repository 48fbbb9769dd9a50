// The configurations of an error-against-run-time sweep: every method asked for, at every
// K (1 for `nearest`, which only ever uses its best source), resolution scale and
// precision. Network variants need weights: a variant is swept only when one of the
// given weight files holds it (its config names the variant); otherwise it is skipped
// with a note that says so, never rendered with made-up weights.
#pragma once

#include <string>
#include <vector>

#include "fvs/eval/evaluate.h"

namespace fvs::eval {

struct SweepOptions {
  std::string methods =
      "nearest,ulr,fvs,fvs_nogru,fvs_nomasks,fvs_noinfdepth,"
      "fvs_single,fvs_fast";
  std::string num_sources = "1,2,3,4,5,6,7,8,auto";  // "auto": adaptive K
  std::string scales = "1,0.5,0.25";
  std::string precisions = "fp32";
  std::string model_paths;  // comma-separated weight files (any variants)

  void Check() const;  // throws fvs::Error for unparsable lists
};

struct SweepPlan {
  std::vector<EvalConfig> configs;
  std::vector<std::string> notes;  // skipped methods and why
};

SweepPlan PlanSweep(const SweepOptions& options);

// "1,0.5" -> {1,0.5} (scales in (0, 4]); throws fvs::Error(option, ...) for anything else.
std::vector<double> ParseDoubleList(const std::string& list, const std::string& option);

// The variant named in a weights file's config (reads the file's header and metadata).
std::string WeightsVariant(const std::string& path);

}  // namespace fvs::eval
