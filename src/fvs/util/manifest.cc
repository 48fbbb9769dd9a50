#include "fvs/util/manifest.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs {
namespace fs = std::filesystem;

namespace {

void StampOne(const fs::path& p, std::ostringstream& out) {
  std::error_code ec;
  const auto size = fs::file_size(p, ec);
  if (ec) return;
  const auto mtime = fs::last_write_time(p, ec);
  if (ec) return;
  out << p.string() << " " << size << " "
      << std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch())
             .count()
      << "\n";
}

}  // namespace

std::string StampPaths(const std::vector<std::string>& paths) {
  std::ostringstream out;
  for (const std::string& path : paths) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) {
      out << path << " missing\n";
      continue;
    }
    if (fs::is_directory(status)) {
      std::vector<fs::path> files;
      for (auto it = fs::recursive_directory_iterator(path, ec);
           !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (it->is_regular_file() &&
            it->path().filename().string().find(".tmp-") == std::string::npos) {
          files.push_back(it->path());
        }
      }
      std::sort(files.begin(), files.end());
      for (const fs::path& f : files) StampOne(f, out);
    } else {
      StampOne(path, out);
    }
  }
  return out.str();
}

Manifest Manifest::Load(const std::string& path) {
  Manifest manifest;
  manifest.path_ = path;
  std::error_code ec;
  if (!fs::exists(path, ec)) return manifest;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadFileToString(path));
    for (const auto& [stage, value] : j.at("stages").items()) {
      Entry e;
      e.fingerprint = value.at("fingerprint").get<std::string>();
      e.outputs = value.at("outputs").get<std::vector<std::string>>();
      e.seconds = value.value("seconds", 0.0);
      manifest.stages_[stage] = e;
    }
  } catch (const std::exception& e) {
    std::cerr << "WARNING: " << path << ": unreadable manifest (" << e.what()
              << "); all stages will run again\n";
    manifest.stages_.clear();
  }
  return manifest;
}

void Manifest::Save() const {
  nlohmann::json j;
  j["format"] = "colmap-fvs manifest 1";
  j["stages"] = nlohmann::json::object();
  for (const auto& [stage, e] : stages_) {
    j["stages"][stage] = {
        {"fingerprint", e.fingerprint}, {"outputs", e.outputs}, {"seconds", e.seconds}};
  }
  WriteFileAtomic(path_, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

std::string Manifest::Fingerprint(const std::vector<std::string>& inputs,
                                  const std::string& options) {
  return "options: " + options + "\n" + StampPaths(inputs);
}

bool Manifest::IsUpToDate(const std::string& stage, const std::string& fingerprint,
                          const std::vector<std::string>& outputs) const {
  const auto it = stages_.find(stage);
  if (it == stages_.end() || it->second.fingerprint != fingerprint) return false;
  if (it->second.outputs != outputs) return false;
  for (const std::string& output : outputs) {
    std::error_code ec;
    if (!fs::exists(output, ec)) return false;
  }
  return true;
}

void Manifest::Record(const std::string& stage, const std::string& fingerprint,
                      const std::vector<std::string>& outputs, double seconds) {
  stages_[stage] = Entry{fingerprint, outputs, seconds};
}

void Manifest::Forget(const std::string& stage) { stages_.erase(stage); }

}  // namespace fvs
