#include "fvs/eval/view_journal.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

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

json ToJson(const ViewResult& r) {
  return {{"scene", r.scene},
          {"method", r.config.method},
          {"num_sources", r.config.num_sources},
          {"scale", r.config.scale},
          {"precision", r.config.precision},
          {"model_path", r.config.model_path},
          {"protocol", r.protocol},
          {"target", r.target},
          {"geometry_holdout", r.geometry_holdout},
          {"psnr", Number(r.psnr)},
          {"ssim", Number(r.ssim)},
          {"lpips", Number(r.lpips)},
          {"psnr_covered", Number(r.psnr_covered)},
          {"ssim_covered", Number(r.ssim_covered)},
          {"seconds", Number(r.seconds)},
          {"cpu_seconds", Number(r.cpu_seconds)},
          {"sources_used", r.sources_used},
          {"coverage", Number(r.coverage)},
          {"mesh_pixels", Number(r.mesh_pixels)},
          {"infinity_pixels", Number(r.infinity_pixels)},
          {"filled_pixels", Number(r.filled_pixels)},
          {"width", r.width},
          {"height", r.height}};
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
  r.psnr = NumberOf(j, "psnr");
  r.ssim = NumberOf(j, "ssim");
  r.lpips = NumberOf(j, "lpips");
  r.psnr_covered = NumberOf(j, "psnr_covered");
  r.ssim_covered = NumberOf(j, "ssim_covered");
  r.seconds = NumberOf(j, "seconds");
  r.cpu_seconds = NumberOf(j, "cpu_seconds");
  r.sources_used = j.at("sources_used").get<int>();
  r.coverage = NumberOf(j, "coverage");
  r.mesh_pixels = NumberOf(j, "mesh_pixels");
  r.infinity_pixels = NumberOf(j, "infinity_pixels");
  r.filled_pixels = NumberOf(j, "filled_pixels");
  r.width = j.at("width").get<int>();
  r.height = j.at("height").get<int>();
  return r;
}

// Image names may hold '/' and spaces; the target's own name inside the entry decides.
std::string FlatName(const std::string& name) {
  std::string flat = name;
  for (char& c : flat) {
    if (c == '/' || c == '\\' || c == ' ') c = '_';
  }
  return flat;
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
  if (discard || previous != settings) fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  Require(!ec, dir, "cannot create the evaluation journal folder: " + ec.message());
  if (discard || previous != settings) {
    WriteFileAtomic(settings_path, [&](std::ostream& out) { out << settings; });
  }
}

std::string ViewJournal::EntryStem(const EvalConfig& config,
                                   const std::string& target) const {
  return (fs::path(dir_) / config.Slug() / FlatName(target)).string();
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
