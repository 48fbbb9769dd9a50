#include "fvs/controllers/sfm_steps.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "colmap_ext/database.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/controllers/prepare_stages.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace fs = std::filesystem;

void RunMatcher(const std::string& type, const std::string& database,
                const std::vector<std::string>& images, const std::string& pairs_path,
                const std::string& gpu, const std::string& threads) {
  const std::vector<std::string> sift = {"--SiftMatching.use_gpu", gpu,
                                         "--SiftMatching.num_threads", threads};
  std::vector<std::string> args;
  const bool spaces = std::any_of(images.begin(), images.end(), [](const std::string& n) {
    return n.find(' ') != std::string::npos;
  });
  if (type == "exhaustive") {
    args = {"exhaustive_matcher", "--database_path", database};
  } else if (spaces) {
    // COLMAP's pair lists split at spaces: its own sequential matcher, no loop closure.
    std::cerr << "  image names with spaces: COLMAP's sequential matcher, without loop "
                 "closure\n";
    args = {"sequential_matcher", "--database_path", database};
  } else {
    WriteFileAtomic(pairs_path, [&](std::ostream& out) {
      for (const auto& [i, j] : SequentialPairs(static_cast<int>(images.size()))) {
        out << images[i] << " " << images[j] << "\n";
      }
    });
    args = {"matches_importer", "--database_path", database, "--match_list_path",
            pairs_path,         "--match_type",    "pairs"};
  }
  args.insert(args.end(), sift.begin(), sift.end());
  colmap::RunColmap(args);
}

namespace {

// Why mapping could not start, from the database: photos with too few features (black,
// blank, blurred, textureless), or no pair of photos that share enough of them. Empty
// when neither explains it.
std::string WhyMappingFound(const std::string& database) {
  constexpr int kMinFeatures = 100;
  colmap::DatabaseContents db;
  try {
    db = colmap::ReadDatabase(database);
  } catch (const Error&) {
    return "";
  }
  int featureless = 0;
  for (const auto& [id, image] : db.images)
    featureless += image.num_keypoints < kMinFeatures;
  const std::string of = " of " + std::to_string(db.images.size()) + " photos";
  if (featureless * 2 > static_cast<int>(db.images.size())) {
    return std::to_string(featureless) + of + " have fewer than " +
           std::to_string(kMinFeatures) +
           " SIFT features (black, blank, blurred or textureless photos?)";
  }
  if (db.num_verified_pairs == 0) {
    return "no two" + of +
           " share enough features (photos of different places, or too little overlap?)";
  }
  return "";
}

}  // namespace

MappedModel MapLargestModel(const std::string& image_path, const std::string& database,
                            const std::string& out, const std::string& threads) {
  colmap::CreateDirectories(out);
  try {
    colmap::RunColmap({"mapper", "--database_path", database, "--image_path", image_path,
                       "--output_path", out, "--Mapper.num_threads", threads});
  } catch (const Error&) {
    // "failed to create sparse model" says nothing of why: the database does.
    const std::string why = WhyMappingFound(database);
    if (why.empty()) throw;
    throw Error(image_path, "SfM registered no photos: " + why);
  }
  MappedModel best;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (!entry.is_directory()) continue;
    const colmap::Reconstruction rec = colmap::ReadSparseModel(entry.path().string());
    if (static_cast<int>(rec.images.size()) > best.registered) {
      best.registered = static_cast<int>(rec.images.size());
      best.path = entry.path().string();
    }
  }
  return best;
}

void WriteRegistrationReport(const std::string& path,
                             const std::vector<std::string>& images,
                             const std::string& model_path, const std::string& matcher,
                             bool retried) {
  const colmap::Reconstruction rec = colmap::ReadSparseModel(model_path);
  std::set<std::string> registered;
  for (const auto& [id, image] : rec.images) registered.insert(image.name);
  nlohmann::json j;
  j["images"] = images.size();
  j["registered"] = registered.size();
  j["matcher"] = matcher;
  j["retried_exhaustive"] = retried;
  j["unregistered"] = nlohmann::json::array();
  for (const std::string& name : images) {
    if (!registered.count(name)) j["unregistered"].push_back(name);
  }
  WriteFileAtomic(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

void ReportRegistration(const std::string& path, const std::set<std::string>& holdout) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ReadFileToString(path));
    j.at("registered").get<int>();
    j.at("images").get<int>();
    j.at("unregistered").get<std::vector<std::string>>();
  } catch (const std::exception& e) {
    std::cerr << "WARNING: " << path << ": unreadable (" << e.what() << ")\n";
    return;
  }
  std::cerr << "SfM registered " << j.at("registered").get<int>() << " of "
            << j.at("images").get<int>() << " images (" << path << ")\n";
  for (const auto& name : j.at("unregistered")) {
    if (holdout.count(name.get<std::string>())) {
      std::cerr << "WARNING: holdout image '" << name.get<std::string>()
                << "' was not registered by SfM: it has no pose, so view_synthesis_eval "
                   "will skip it\n";
    }
  }
}

}  // namespace fvs
