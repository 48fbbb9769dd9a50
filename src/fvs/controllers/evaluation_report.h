// The files and the terminal summary of an evaluation (evaluation.h).
#pragma once

#include <cstddef>
#include <vector>

#include "fvs/controllers/evaluation.h"
#include "fvs/eval/evaluate.h"

namespace fvs {

// The configuration the contact sheet shows, its rows and their thumbnails.
struct ContactSheetViews {
  eval::EvalConfig config;
  std::vector<eval::ViewResult> results;
  std::vector<eval::ViewThumbnails> thumbnails;
};

// Writes results.csv, summary.csv, results.md and machine.txt into options.output_path,
// the contact sheet (thumbnail_width > 0) and, for more than one configuration, the plot
// of quality against time (a plot that cannot be drawn is a warning on stderr).
void WriteEvaluationReports(const EvaluationOptions& options,
                            const EvaluationResult& result,
                            const ContactSheetViews& sheet, size_t num_configs);

}  // namespace fvs
