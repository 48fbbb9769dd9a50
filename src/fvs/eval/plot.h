// Error against run time as a PNG, drawn without a plotting library: mean PSNR of each
// configuration against its mean seconds per view on a log-scale time axis, one curve
// per method (and resolution scale / precision) through its K values, Pareto-optimal
// points ringed in black and labelled with their K, a legend, and the machine.
#pragma once

#include <string>
#include <vector>

#include "fvs/eval/report.h"

namespace fvs::eval {

struct PlotOptions {
  int width = 960;
  int height = 600;
  std::string title = "Quality against run time";
  std::string footer;                     // e.g. the machine
  TimeMeasure time = TimeMeasure::kWall;  // the x axis
};

// Configurations without a finite PSNR and time are left out. Throws fvs::Error when no
// configuration is left.
Image PlotErrorAgainstTime(const std::vector<ConfigSummary>& summary,
                           const PlotOptions& options);

// Ticks of a 1-2-5 "nice" step covering [lo, hi] (at least two).
std::vector<double> NiceTicks(double lo, double hi, int target_count);

}  // namespace fvs::eval
