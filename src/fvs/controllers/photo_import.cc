#include "fvs/controllers/photo_import.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;

std::string CameraKey(const colmap::PhotoMetadata& m) {
  char focal[32];
  std::snprintf(focal, sizeof(focal), "%.2f", m.focal_length_mm);
  return m.make + "|" + m.model + "|" + m.lens + "|" + focal + "mm|" +
         std::to_string(m.width()) + "x" + std::to_string(m.height());
}

}  // namespace

bool PhotoImportPlan::needed() const { return num_converted() > 0; }

int PhotoImportPlan::num_converted() const {
  return static_cast<int>(std::count_if(photos.begin(), photos.end(),
                                        [](const PlannedPhoto& p) { return p.convert; }));
}

std::vector<std::vector<std::string>> PhotoImportPlan::CameraGroups() const {
  std::vector<std::string> keys;
  std::vector<std::vector<std::string>> groups;
  for (const PlannedPhoto& p : photos) {
    const auto it = std::find(keys.begin(), keys.end(), p.camera);
    if (it == keys.end()) {
      keys.push_back(p.camera);
      groups.push_back({p.name});
    } else {
      groups[it - keys.begin()].push_back(p.name);
    }
  }
  return groups;
}

std::string PhotoImportPlan::NameOf(const std::string& user_name) const {
  for (const PlannedPhoto& p : photos) {
    if (p.source == user_name || p.name == user_name) return p.name;
  }
  throw Error(user_name, "is not one of the photos");
}

PhotoImportPlan PlanPhotoImport(const std::string& folder,
                                const std::vector<std::string>& names) {
  PhotoImportPlan plan;
  for (const std::string& source : names) {
    PlannedPhoto p;
    p.source = source;
    p.metadata = colmap::ReadPhotoMetadata(JoinPaths(folder, source));
    const bool heif = p.metadata.format == "heif";
    p.convert = heif || p.metadata.orientation != 1;
    p.name = heif ? source + ".jpg" : source;
    p.camera = CameraKey(p.metadata);
    plan.photos.push_back(std::move(p));
  }
  return plan;
}

void ImportPhotos(const PhotoImportPlan& plan, const std::string& source_folder,
                  const std::string& target_folder) {
  std::error_code ec;
  fs::create_directories(target_folder, ec);
  Require(!ec, target_folder, "cannot create the folder: " + ec.message());
  for (const PlannedPhoto& p : plan.photos) {
    const std::string source = JoinPaths(source_folder, p.source);
    const std::string target = JoinPaths(target_folder, p.name);
    fs::remove(target, ec);
    if (p.convert) {
      colmap::WriteUprightPhoto(source, target);
      continue;
    }
    fs::create_symlink(fs::absolute(source), target, ec);
    Require(!ec, target, "cannot link to " + source + ": " + ec.message());
  }
}

}  // namespace fvs
