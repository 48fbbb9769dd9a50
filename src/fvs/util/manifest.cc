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

void StampOne(const fs::path& p, const std::string& root, std::ostringstream& out) {
  std::error_code ec;
  const auto size = fs::file_size(p, ec);
  if (ec) return;
  const auto mtime = fs::last_write_time(p, ec);
  if (ec) return;
  out << PathInside(p.string(), root) << " " << size << " "
      << std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch())
             .count()
      << "\n";
}

// The folder holding every path of `paths` (their longest common parent).
std::string CommonFolder(const std::vector<std::string>& paths) {
  if (paths.empty()) return "";
  fs::path common = fs::path(paths[0]).parent_path();
  for (const std::string& p : paths) {
    while (!common.empty() && PathInside(p, common.string()) == p) {
      common = common.parent_path() == common ? fs::path() : common.parent_path();
    }
  }
  return common.string();
}

}  // namespace

std::string PathInside(const std::string& path, const std::string& root) {
  if (root.empty() || path.empty() || path[0] != '/') return path;
  const fs::path relative = fs::path(path).lexically_normal().lexically_relative(
      fs::path(root).lexically_normal());
  if (relative.empty() || *relative.begin() == "..") return path;
  return relative.string();
}

std::string StampPaths(const std::vector<std::string>& paths, const std::string& root) {
  std::ostringstream out;
  for (const std::string& path : paths) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) {
      out << PathInside(path, root) << " missing\n";
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
      for (const fs::path& f : files) StampOne(f, root, out);
    } else {
      StampOne(path, root, out);
    }
  }
  return out.str();
}

Manifest Manifest::Load(const std::string& path, const std::string& root) {
  Manifest manifest;
  manifest.path_ = path;
  manifest.root_ = root;
  std::error_code ec;
  if (!fs::exists(path, ec)) return manifest;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadFileToString(path));
    std::vector<std::string> all_outputs;
    for (const auto& [stage, value] : j.at("stages").items()) {
      Entry e;
      e.fingerprint = value.at("fingerprint").get<std::string>();
      e.outputs = value.at("outputs").get<std::vector<std::string>>();
      e.seconds = value.value("seconds", 0.0);
      manifest.stages_[stage] = e;
      all_outputs.insert(all_outputs.end(), e.outputs.begin(), e.outputs.end());
    }
    // Format 1 recorded absolute outputs: relative to the folder that held them all
    // (the workspace, wherever it was then).
    if (j.value("format", "") == "colmap-fvs manifest 1" && !root.empty()) {
      const std::string old_root = CommonFolder(all_outputs);
      for (auto& [stage, e] : manifest.stages_) {
        for (std::string& output : e.outputs) output = PathInside(output, old_root);
      }
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
  j["format"] = "colmap-fvs manifest 2";
  j["stages"] = nlohmann::json::object();
  for (const auto& [stage, e] : stages_) {
    j["stages"][stage] = {
        {"fingerprint", e.fingerprint}, {"outputs", e.outputs}, {"seconds", e.seconds}};
  }
  WriteFileAtomic(path_, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

std::string Manifest::Fingerprint(const std::vector<std::string>& inputs,
                                  const std::string& options, const std::string& root) {
  return "options: " + options + "\n" + StampPaths(inputs, root);
}

std::string Manifest::Recorded(const std::string& output) const {
  return PathInside(output, root_);
}

std::string Manifest::Resolved(const std::string& recorded) const {
  if (root_.empty() || recorded.empty() || recorded[0] == '/') return recorded;
  return (fs::path(root_) / recorded).string();
}

bool Manifest::IsUpToDate(const std::string& stage, const std::string& fingerprint,
                          const std::vector<std::string>& outputs) const {
  const auto it = stages_.find(stage);
  if (it == stages_.end() || it->second.fingerprint != fingerprint) return false;
  if (it->second.outputs.size() != outputs.size()) return false;
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (it->second.outputs[i] != Recorded(outputs[i])) return false;
    std::error_code ec;
    if (!fs::exists(Resolved(it->second.outputs[i]), ec)) return false;
  }
  return true;
}

void Manifest::Record(const std::string& stage, const std::string& fingerprint,
                      const std::vector<std::string>& outputs, double seconds) {
  Entry entry{fingerprint, {}, seconds};
  for (const std::string& output : outputs) entry.outputs.push_back(Recorded(output));
  stages_[stage] = entry;
}

void Manifest::Forget(const std::string& stage) { stages_.erase(stage); }

}  // namespace fvs
