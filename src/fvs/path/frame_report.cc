#include "fvs/path/frame_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fvs/util/atomic_file.h"
#include "fvs/util/string_util.h"

namespace fvs {

namespace {

constexpr const char* kHeader =
    "frame,status,coverage,flagged,sources,source_changes,flicker,covisible,seconds,"
    "temporal_seconds,psnr";
// Reports written before the PSNR column are read too.
constexpr const char* kHeaderWithoutPsnr =
    "frame,status,coverage,flagged,sources,source_changes,flicker,covisible,seconds,"
    "temporal_seconds";

double ParseOr(const std::string& s, double fallback) {
  try {
    size_t used = 0;
    const double v = std::stod(s, &used);
    return used == s.size() && std::isfinite(v) ? v : fallback;
  } catch (const std::exception&) {
    return fallback;
  }
}

}  // namespace

std::map<std::string, FrameReportRow> ReadFrameReport(const std::string& csv_path) {
  std::map<std::string, FrameReportRow> rows;
  std::ifstream in(csv_path);
  if (!in.good()) return rows;
  std::string line;
  if (!std::getline(in, line)) return rows;
  const std::string header = TrimString(line);
  if (header != kHeader && header != kHeaderWithoutPsnr) return rows;
  const size_t fields = header == kHeader ? 11 : 10;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) f.push_back(cell);
    if (f.size() != fields || f[0].empty()) continue;
    FrameReportRow r;
    r.frame = f[0];
    r.status = f[1];
    r.coverage = ParseOr(f[2], -1);
    r.flagged = f[3] == "1";
    r.sources = f[4];
    r.source_changes = static_cast<int>(ParseOr(f[5], -1));
    r.flicker = ParseOr(f[6], -1);
    r.covisible = ParseOr(f[7], -1);
    r.seconds = ParseOr(f[8], -1);
    r.temporal_seconds = ParseOr(f[9], -1);
    if (fields == 11) r.psnr = ParseOr(f[10], -1);
    rows[r.frame] = r;
  }
  return rows;
}

FrameReportSummary SummariseFrameReport(const std::vector<FrameReportRow>& rows,
                                        double coverage_threshold) {
  FrameReportSummary s;
  s.coverage_threshold = coverage_threshold;
  s.num_frames = static_cast<int>(rows.size());
  double coverage = 0, flicker = 0, flicker_w = 0, changes = 0, seconds = 0, temporal = 0,
         psnr = 0;
  int n_coverage = 0, n_changes = 0, n_seconds = 0;
  for (const FrameReportRow& r : rows) {
    (r.status == "rendered" ? s.num_rendered : s.num_resumed)++;
    if (r.flagged) s.flagged.push_back(r.frame);
    if (r.coverage >= 0) {
      coverage += r.coverage;
      ++n_coverage;
    }
    if (r.flicker >= 0 && r.covisible > 0) {
      flicker += r.flicker * r.covisible;
      flicker_w += r.covisible;
    }
    if (r.psnr >= 0) {
      psnr += r.psnr;
      ++s.num_psnr;
    }
    if (r.source_changes >= 0) {
      changes += r.source_changes;
      ++n_changes;
    }
    if (r.status == "rendered" && r.seconds >= 0) {
      seconds += r.seconds;
      temporal += std::max(0.0, r.temporal_seconds);
      ++n_seconds;
    }
  }
  s.mean_coverage = n_coverage ? coverage / n_coverage : 0;
  if (flicker_w > 0) s.mean_flicker = flicker / flicker_w;
  if (n_changes) s.mean_source_changes = changes / n_changes;
  if (s.num_psnr) s.mean_psnr = psnr / s.num_psnr;
  if (n_seconds) {
    s.mean_seconds = seconds / n_seconds;
    s.mean_temporal_seconds = temporal / n_seconds;
  }
  return s;
}

void WriteFrameReport(const std::string& stem, const std::vector<FrameReportRow>& rows,
                      const FrameReportSummary& summary, const std::string& extra_json) {
  WriteFileAtomic(stem + ".csv", [&](std::ostream& out) {
    out << kHeader << "\n";
    char buffer[512];
    for (const FrameReportRow& r : rows) {
      std::snprintf(buffer, sizeof(buffer),
                    "%s,%s,%.6f,%d,%s,%d,%.6f,%.6f,%.6f,%.6f,%.4f\n", r.frame.c_str(),
                    r.status.c_str(), r.coverage, r.flagged ? 1 : 0, r.sources.c_str(),
                    r.source_changes, r.flicker, r.covisible, r.seconds,
                    r.temporal_seconds, r.psnr);
      out << buffer;
    }
  });
  nlohmann::json json = nlohmann::json::object();
  if (!extra_json.empty()) json = nlohmann::json::parse(extra_json);
  json["num_frames"] = summary.num_frames;
  json["num_rendered"] = summary.num_rendered;
  json["num_resumed"] = summary.num_resumed;
  json["coverage_threshold"] = summary.coverage_threshold;
  json["flagged_frames"] = summary.flagged;
  json["mean_coverage"] = summary.mean_coverage;
  json["mean_flicker_levels"] = summary.mean_flicker;
  json["mean_source_changes"] = summary.mean_source_changes;
  json["mean_psnr"] = summary.mean_psnr;
  json["num_frames_with_ground_truth"] = summary.num_psnr;
  json["mean_seconds_per_frame"] = summary.mean_seconds;
  json["mean_temporal_seconds_per_frame"] = summary.mean_temporal_seconds;
  WriteFileAtomic(stem + ".json",
                  [&](std::ostream& out) { out << json.dump(2) << "\n"; });
}

}  // namespace fvs
