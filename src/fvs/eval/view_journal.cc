#include "fvs/eval/view_journal.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "colmap_ext/image_io.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr char kSettingsFile[] = "settings.json";

// NaN (not available) is JSON null; doubles round-trip exactly (shortest form).
json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

double NumberOf(const json& j, const char* key) {
  const json& value = j.at(key);
  return value.is_null() ? kNotAvailable : value.get<double>();
}

// The identity of a view, then ViewResult::ForEachMeasure's fields.
json ToJson(const ViewResult& r) {
  json j = {{"scene", r.scene},
            {"method", r.config.method},
            {"num_sources", r.config.num_sources},
            {"scale", r.config.scale},
            {"precision", r.config.precision},
            {"model_path", r.config.model_path},
            {"protocol", r.protocol},
            {"target", r.target},
            {"geometry_holdout", r.geometry_holdout}};
  ViewResult::ForEachMeasure(r, [&](const char* name, const auto& value, int) {
    if constexpr (std::is_same_v<std::decay_t<decltype(value)>, int>) {
      j[name] = value;
    } else {
      j[name] = Number(value);
    }
  });
  return j;
}

ViewResult FromJson(const json& j) {
  ViewResult r;
  r.scene = j.at("scene").get<std::string>();
  r.config.method = j.at("method").get<std::string>();
  r.config.num_sources = j.at("num_sources").get<int>();
  r.config.scale = j.at("scale").get<double>();
  r.config.precision = j.at("precision").get<std::string>();
  r.config.model_path = j.at("model_path").get<std::string>();
  r.protocol = j.at("protocol").get<std::string>();
  r.target = j.at("target").get<std::string>();
  r.geometry_holdout = j.at("geometry_holdout").get<bool>();
  ViewResult::ForEachMeasure(r, [&](const char* name, auto& value, int) {
    if constexpr (std::is_same_v<std::decay_t<decltype(value)>, int>) {
      value = j.at(name).get<int>();
    } else {
      value = NumberOf(j, name);
    }
  });
  return r;
}

}  // namespace

ViewJournal::ViewJournal(const std::string& dir, const std::string& settings,
                         bool discard)
    : dir_(dir) {
  const std::string settings_path = (fs::path(dir) / kSettingsFile).string();
  std::string previous;
  std::error_code ec;
  if (fs::is_regular_file(settings_path, ec)) {
    try {
      previous = ReadFileToString(settings_path);
    } catch (const Error&) {
    }
  }
  // Entries of other settings (or all, when asked) are never reused: start afresh.
  const bool fresh = discard || previous != settings;
  if (fresh) fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  Require(!ec, dir, "cannot create the evaluation journal folder: " + ec.message());
  if (fresh) {
    WriteFileAtomic(settings_path, [&](std::ostream& out) { out << settings; });
  }
}

std::string ViewJournal::EntryStem(const EvalConfig& config,
                                   const std::string& target) const {
  return (fs::path(dir_) / config.Slug() / FlatImageName(target)).string();
}

bool ViewJournal::Find(const EvalConfig& config, const std::string& target,
                       ViewResult* result, Image* thumbnail) const {
  const std::string stem = EntryStem(config, target);
  std::error_code ec;
  if (!fs::is_regular_file(stem + ".json", ec)) return false;
  try {
    ViewResult r = FromJson(json::parse(ReadFileToString(stem + ".json")));
    if (r.target != target || r.config.Label() != config.Label()) return false;
    if (thumbnail) {
      *thumbnail = Image();
      if (fs::is_regular_file(stem + ".thumb.tif", ec)) {
        *thumbnail = colmap::ReadImage(stem + ".thumb.tif");
      }
    }
    *result = std::move(r);
    return true;
  } catch (const std::exception&) {
    return false;  // damaged: evaluated again
  }
}

void ViewJournal::Record(const ViewResult& result, const Image& thumbnail) const {
  if (!result.ok()) return;
  const std::string stem = EntryStem(result.config, result.target);
  std::error_code ec;
  fs::create_directories(fs::path(stem).parent_path(), ec);
  Require(!ec, fs::path(stem).parent_path().string(),
          "cannot create the evaluation journal folder: " + ec.message());
  // The thumbnail first: the .json is what makes the entry count.
  if (!thumbnail.empty()) colmap::WriteImage(stem + ".thumb.tif", thumbnail, 32);
  WriteFileAtomic(stem + ".json",
                  [&](std::ostream& out) { out << ToJson(result).dump(1) << "\n"; });
}

}  // namespace fvs::eval
