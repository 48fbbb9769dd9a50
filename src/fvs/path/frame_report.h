// The per-frame report of a rendered video (O/frame_report.csv and a summary in
// O/frame_report.json): coverage of every frame, frames flagged under a coverage
// threshold, the sources used and how many changed since the previous frame, the flicker
// to the previous frame, the PSNR against a ground-truth image where there is one and the
// render time. A resumed render keeps the rows of the frames it skipped from the previous
// report.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace fvs {

struct FrameReportRow {
  std::string frame;
  std::string status = "rendered";  // rendered | resumed
  double coverage = -1;             // fraction of pixels with a contribution; -1 unknown
  bool flagged = false;             // coverage under the threshold
  std::string sources;              // view indices, ';' separated, in blend order
  int source_changes = -1;          // sources not used by the previous frame; -1 unknown
  double flicker = -1;              // 8-bit levels to the previous frame; -1 unknown
  double covisible = -1;            // fraction of pixels compared for the flicker
  double psnr = -1;                 // dB against the ground-truth frame; -1 none
  double seconds = -1;              // render time, all included
  double temporal_seconds = -1;     // of which the temporal blend and flicker
};

struct FrameReportSummary {
  int num_frames = 0;
  int num_rendered = 0;
  int num_resumed = 0;
  std::vector<std::string> flagged;
  double coverage_threshold = 0.5;
  double mean_coverage = 0;  // over frames with a known coverage
  double mean_flicker = -1;  // over known pairs, weighted by compared pixels
  double mean_source_changes = -1;
  double mean_psnr = -1;  // over frames with ground truth
  int num_psnr = 0;
  double mean_seconds = -1;           // per rendered frame
  double mean_temporal_seconds = -1;  // of which blend + flicker
};

// Rows of an earlier report by frame name (empty when there is none or it is unreadable).
std::map<std::string, FrameReportRow> ReadFrameReport(const std::string& csv_path);

FrameReportSummary SummariseFrameReport(const std::vector<FrameReportRow>& rows,
                                        double coverage_threshold);

// Writes <stem>.csv and <stem>.json (atomic; stem is e.g. O/frame_report); `extra` is
// merged into the JSON summary (method, options, machine).
void WriteFrameReport(const std::string& stem, const std::vector<FrameReportRow>& rows,
                      const FrameReportSummary& summary, const std::string& extra_json);

}  // namespace fvs
