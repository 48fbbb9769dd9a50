#include "fvs/eval/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <type_traits>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::eval {
namespace {

// The columns that say which view and run a row is, before its measured fields.
const std::vector<std::string> kIdentityColumns = {
    "scene",    "method", "num_sources",      "scale", "precision",
    "protocol", "target", "geometry_holdout", "status"};
// The identity columns, ViewResult::ForEachMeasure's, then the error message.
std::vector<std::string> Columns() {
  std::vector<std::string> columns = kIdentityColumns;
  const ViewResult names;
  ViewResult::ForEachMeasure(
      names, [&](const char* name, const auto&, int) { columns.push_back(name); });
  columns.push_back("error");
  return columns;
}
const std::vector<std::string> kColumns = Columns();
const size_t kFirstMeasureColumn = kIdentityColumns.size();
// Measure columns added after results.csv files were first written, oldest first: a
// file may lack any trailing group of them (it was written before they existed), and
// reads them as n/a.
const std::vector<std::vector<std::string>> kAddedColumnGroups = {
    {"mesh_pixels", "infinity_pixels", "filled_pixels"}, {"filled_seen_pixels"}};

// For each column of kColumns, its index in a file whose header is `header`, or -1 where
// the file predates the column. Empty when the header is no results.csv header we wrote.
std::vector<int> ColumnIndicesOf(const std::vector<std::string>& header) {
  for (size_t kept = kAddedColumnGroups.size() + 1; kept-- > 0;) {
    std::vector<std::string> missing;
    for (size_t g = kept; g < kAddedColumnGroups.size(); ++g) {
      missing.insert(missing.end(), kAddedColumnGroups[g].begin(),
                     kAddedColumnGroups[g].end());
    }
    std::vector<std::string> expected;
    for (const std::string& c : kColumns) {
      if (std::find(missing.begin(), missing.end(), c) == missing.end()) {
        expected.push_back(c);
      }
    }
    if (header != expected) continue;
    std::vector<int> indices;
    for (const std::string& c : kColumns) {
      const auto at = std::find(header.begin(), header.end(), c);
      indices.push_back(at == header.end() ? -1 : static_cast<int>(at - header.begin()));
    }
    return indices;
  }
  return {};
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string quoted = "\"";
  for (char c : s) {
    if (c == '\n' || c == '\r') c = ' ';  // one record per line
    quoted += c;
    if (c == '"') quoted += '"';
  }
  return quoted + "\"";
}

// Splits one CSV line (RFC 4180 quoting, no embedded newlines).
bool SplitCsvLine(const std::string& line, std::vector<std::string>* fields) {
  fields->clear();
  std::string field;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields->push_back(field);
      field.clear();
    } else if (c != '\r') {
      field += c;
    }
  }
  fields->push_back(field);
  return !quoted;
}

double ParseNumber(const std::string& s, const std::string& where) {
  if (s == "n/a" || s.empty()) return kNotAvailable;
  try {
    size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw Error(where, "'" + s + "' is not a number");
}

int ParseInt(const std::string& s, const std::string& where) {
  const double v = ParseNumber(s, where);
  Require(std::isfinite(v) && v == std::floor(v), where, "'" + s + "' is not an integer");
  return static_cast<int>(v);
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return kNotAvailable;
  double sum = 0;
  for (double v : values) sum += v;
  return sum / values.size();
}

}  // namespace

std::string FormatNumber(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

TimeMeasure ParseTimeMeasure(const std::string& name) {
  if (name == "wall") return TimeMeasure::kWall;
  Require(name == "cpu", "--time", "must be wall or cpu, not '" + name + "'");
  return TimeMeasure::kCpu;
}

std::vector<ConfigSummary> Summarize(const std::vector<ViewResult>& results,
                                     TimeMeasure time) {
  std::vector<ConfigSummary> summary;
  std::map<std::string, size_t> slot;
  struct Sums {
    std::vector<double> psnr, ssim, lpips, psnr_covered, ssim_covered, seconds, cpu,
        sources;
  };
  std::vector<Sums> sums;
  for (const ViewResult& r : results) {
    const std::string key = r.config.Label();
    auto it = slot.find(key);
    if (it == slot.end()) {
      it = slot.emplace(key, summary.size()).first;
      summary.push_back({});
      summary.back().config = r.config;
      sums.emplace_back();
    }
    ConfigSummary& s = summary[it->second];
    Sums& t = sums[it->second];
    if (!r.ok()) {
      s.views_failed += r.failed();
      continue;
    }
    ++s.views_ok;
    t.psnr.push_back(r.psnr);
    t.ssim.push_back(r.ssim);
    if (std::isfinite(r.lpips)) t.lpips.push_back(r.lpips);
    if (std::isfinite(r.psnr_covered)) t.psnr_covered.push_back(r.psnr_covered);
    if (std::isfinite(r.ssim_covered)) t.ssim_covered.push_back(r.ssim_covered);
    t.seconds.push_back(r.seconds);
    if (std::isfinite(r.cpu_seconds)) t.cpu.push_back(r.cpu_seconds);
    t.sources.push_back(r.sources_used);
  }
  for (size_t i = 0; i < summary.size(); ++i) {
    ConfigSummary& s = summary[i];
    s.psnr = Mean(sums[i].psnr);
    s.ssim = Mean(sums[i].ssim);
    s.seconds = Mean(sums[i].seconds);
    s.cpu_seconds = Mean(sums[i].cpu);
    s.psnr_covered = Mean(sums[i].psnr_covered);
    s.ssim_covered = Mean(sums[i].ssim_covered);
    s.sources_used = Mean(sums[i].sources);
    if (!sums[i].lpips.empty() && static_cast<int>(sums[i].lpips.size()) == s.views_ok) {
      s.lpips = Mean(sums[i].lpips);
    }
  }
  // Pareto front over (time lower, PSNR higher); ties in both keep both.
  for (ConfigSummary& s : summary) {
    if (!std::isfinite(s.psnr) || !std::isfinite(s.Time(time))) continue;
    s.pareto = true;
    for (const ConfigSummary& o : summary) {
      if (&o == &s || !std::isfinite(o.psnr) || !std::isfinite(o.Time(time))) continue;
      const bool no_worse = o.Time(time) <= s.Time(time) && o.psnr >= s.psnr;
      const bool better = o.Time(time) < s.Time(time) || o.psnr > s.psnr;
      if (no_worse && better) {
        s.pareto = false;
        break;
      }
    }
  }
  return summary;
}

void WriteResultsCsv(const std::string& path, const std::vector<ViewResult>& results) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    for (size_t i = 0; i < kColumns.size(); ++i) out << (i ? "," : "") << kColumns[i];
    out << "\n";
    for (const ViewResult& r : results) {
      char scale[32];
      std::snprintf(scale, sizeof(scale), "%g", r.config.scale);
      out << CsvField(r.scene) << "," << CsvField(r.config.method) << ","
          << FormatNumSources(r.config.num_sources) << "," << scale << ","
          << CsvField(r.config.precision) << "," << CsvField(r.protocol) << ","
          << CsvField(r.target) << "," << (r.geometry_holdout ? "yes" : "no") << ","
          << (r.ok()      ? "ok"
              : r.skipped ? "skipped"
                          : "error");
      ViewResult::ForEachMeasure(r, [&](const char*, const auto& value, int decimals) {
        out << ",";
        if constexpr (std::is_same_v<std::decay_t<decltype(value)>, int>) {
          out << value;
        } else {
          out << FormatNumber(value, decimals);
        }
      });
      out << "," << CsvField(r.error) << "\n";
    }
  });
}

std::vector<ViewResult> ReadResultsCsv(const std::string& path) {
  std::istringstream in(ReadFileToString(path));
  std::string line;
  std::vector<std::string> fields;
  Require(static_cast<bool>(std::getline(in, line)), path, "empty file");
  SplitCsvLine(line, &fields);
  const std::vector<int> indices = ColumnIndicesOf(fields);
  Require(!indices.empty(), path, "line 1: not a view_synthesis_eval results.csv header");
  const size_t file_columns = fields.size();
  std::vector<ViewResult> results;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty() || line == "\r") continue;
    const std::string where = path + ":" + std::to_string(number);
    Require(SplitCsvLine(line, &fields), where, "unterminated quote");
    Require(fields.size() == file_columns, where,
            std::to_string(fields.size()) + " fields, expected " +
                std::to_string(file_columns));
    std::vector<std::string> in_file = std::move(fields);
    fields.clear();
    for (int i : indices) fields.push_back(i < 0 ? "n/a" : in_file[i]);
    ViewResult r;
    r.scene = fields[0];
    r.config.method = fields[1];
    r.config.num_sources = ParseNumSources(fields[2], where);
    r.config.scale = ParseNumber(fields[3], where);
    r.config.precision = fields[4];
    r.protocol = fields[5];
    r.target = fields[6];
    r.geometry_holdout = fields[7] == "yes";
    const bool ok = fields[8] == "ok";
    r.skipped = fields[8] == "skipped";
    Require(ok || r.skipped || fields[8] == "error", where,
            "status must be ok, skipped or error");
    size_t column = kFirstMeasureColumn;
    ViewResult::ForEachMeasure(r, [&](const char*, auto& value, int) {
      if constexpr (std::is_same_v<std::decay_t<decltype(value)>, int>) {
        value = ParseInt(fields[column++], where);
      } else {
        value = ParseNumber(fields[column++], where);
      }
    });
    r.error = fields.back();
    if (ok) {
      Require(r.error.empty(), where, "status ok with an error message");
      Require(std::isfinite(r.psnr) && std::isfinite(r.ssim) && std::isfinite(r.seconds),
              where, "status ok without psnr, ssim and seconds");
    } else if (r.error.empty()) {
      r.error = r.skipped ? "skipped (no reason)" : "error (no message)";
    }
    results.push_back(std::move(r));
  }
  return results;
}

void WriteSummaryCsv(const std::string& path, const std::vector<ConfigSummary>& summary) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << "method,num_sources,scale,precision,views_ok,views_failed,psnr,ssim,lpips,"
           "psnr_covered,ssim_covered,"
           "seconds_per_view,cpu_seconds_per_view,sources_used,pareto\n";
    for (const ConfigSummary& s : summary) {
      char scale[32];
      std::snprintf(scale, sizeof(scale), "%g", s.config.scale);
      out << CsvField(s.config.method) << "," << FormatNumSources(s.config.num_sources)
          << "," << scale << "," << CsvField(s.config.precision) << "," << s.views_ok
          << "," << s.views_failed << "," << FormatNumber(s.psnr, 4) << ","
          << FormatNumber(s.ssim, 5) << "," << FormatNumber(s.lpips, 5) << ","
          << FormatNumber(s.psnr_covered, 4) << "," << FormatNumber(s.ssim_covered, 5)
          << "," << FormatNumber(s.seconds, 4) << "," << FormatNumber(s.cpu_seconds, 4)
          << "," << FormatNumber(s.sources_used, 2) << "," << (s.pareto ? "yes" : "no")
          << "\n";
    }
  });
}

void WriteMarkdownReport(const std::string& path, const ReportHeader& context,
                         const std::vector<ViewResult>& results,
                         const std::vector<ConfigSummary>& summary) {
  auto cell = [](const std::string& s) {
    std::string out;
    for (char c : s) out += (c == '|') ? std::string("\\|") : std::string(1, c);
    return out;
  };
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << "# " << context.title << "\n\n";
    if (!context.workspace.empty()) out << "- workspace: `" << context.workspace << "`\n";
    if (!context.machine.empty()) out << "- machine: " << context.machine << "\n";
    for (const std::string& note : context.notes) out << "- " << note << "\n";
    out << "\n## Per configuration (means over the evaluated views)\n\n";
    out << "| method | K | scale | precision | views | failed | PSNR | SSIM | LPIPS | "
           "PSNR covered | SSIM covered | s/view | CPU s/view | K used | Pareto |\n";
    out << "| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
           "---: | ---: | ---: | --- |\n";
    for (const ConfigSummary& s : summary) {
      char scale[32];
      std::snprintf(scale, sizeof(scale), "%g", s.config.scale);
      out << "| " << cell(s.config.method) << " | "
          << FormatNumSources(s.config.num_sources) << " | " << scale << " | "
          << s.config.precision << " | " << s.views_ok << " | " << s.views_failed << " | "
          << FormatNumber(s.psnr, 2) << " | " << FormatNumber(s.ssim, 4) << " | "
          << FormatNumber(s.lpips, 4) << " | " << FormatNumber(s.psnr_covered, 2) << " | "
          << FormatNumber(s.ssim_covered, 4) << " | " << FormatNumber(s.seconds, 3)
          << " | " << FormatNumber(s.cpu_seconds, 3) << " | "
          << FormatNumber(s.sources_used, 1) << " | " << (s.pareto ? "yes" : "")
          << " |\n";
    }
    out << "\n## Per view\n\n";
    out << "| configuration | target | held out of the mesh | PSNR | SSIM | LPIPS | "
           "PSNR covered | SSIM covered | s | CPU s | K used | coverage | error |\n";
    out << "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
           "---: "
           "| --- |\n";
    for (const ViewResult& r : results) {
      out << "| " << cell(r.config.Label()) << " | " << cell(r.target) << " | "
          << (r.geometry_holdout ? "yes" : "no") << " | " << FormatNumber(r.psnr, 2)
          << " | " << FormatNumber(r.ssim, 4) << " | " << FormatNumber(r.lpips, 4)
          << " | " << FormatNumber(r.psnr_covered, 2) << " | "
          << FormatNumber(r.ssim_covered, 4) << " | " << FormatNumber(r.seconds, 3)
          << " | " << FormatNumber(r.cpu_seconds, 3) << " | " << r.sources_used << " | "
          << FormatNumber(100 * r.coverage, 1) << (r.ok() ? "%" : "") << " | "
          << (r.skipped ? "skipped: " : "") << cell(r.error) << " |\n";
    }
  });
}

}  // namespace fvs::eval
