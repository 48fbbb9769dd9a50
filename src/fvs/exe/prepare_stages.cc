#include "fvs/exe/prepare_stages.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "colmap_ext/image_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/exe/command_registry.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/manifest.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace fs = std::filesystem;

namespace {

const char* kWho = "colmap view_synthesis_prepare";

// FNV-1a: a stable digest for chaining fingerprints (std::hash is not stable across
// builds).
std::string Digest(const std::string& text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  std::ostringstream s;
  s << std::hex << h;
  return s.str();
}

void RemoveAll(const std::string& path) {
  std::error_code ec;
  fs::remove_all(path, ec);
}

// Replaces `to` by `from` (both folders or files) as atomically as the file system
// allows: the old output is moved aside first, so at every instant either the old or the
// new one is complete.
void MoveIntoPlace(const std::string& from, const std::string& to) {
  std::error_code ec;
  const std::string old = to + ".old-fvs";
  RemoveAll(old);
  if (fs::exists(to, ec)) fs::rename(to, old, ec);
  fs::rename(from, to, ec);
  if (ec) throw Error(to, "cannot move stage output into place (" + ec.message() + ")");
  RemoveAll(old);
}

std::vector<std::string> CommandArgs(const std::string& command,
                                     const std::vector<std::string>& options) {
  std::vector<std::string> args = {"colmap", command};
  args.insert(args.end(), options.begin(), options.end());
  return args;
}

// Runs one of our registered commands in-process.
void RunOurCommand(const std::string& command, const std::vector<std::string>& options) {
  const CommandInfo* info = FindCommand(command);
  if (info == nullptr) {
    throw Error(kWho, "this build has no " + command + " command");
  }
  std::vector<std::string> args = CommandArgs(command, options);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int status = info->function(static_cast<int>(args.size()), argv.data());
  if (status != 0)
    throw Error(kWho, command + " failed (exit " + std::to_string(status) + ")");
}

struct StageRunner {
  Manifest manifest;
  std::string previous;  // chained fingerprint digest
  int index = 0;
  int total = 0;

  // Runs `run` unless the manifest says the stage is up to date.
  void Run(const std::string& name, const std::vector<std::string>& inputs,
           const std::string& options, const std::vector<std::string>& outputs,
           const std::function<void()>& run) {
    ++index;
    const std::string fingerprint =
        Digest(previous + "\n" + Manifest::Fingerprint(inputs, options, manifest.root()));
    previous = fingerprint;
    if (manifest.IsUpToDate(name, fingerprint, outputs)) {
      std::cerr << "[" << index << "/" << total << "] " << name
                << ": up to date, skipped\n";
      return;
    }
    std::cerr << "[" << index << "/" << total << "] " << name << " ...\n";
    manifest.Forget(name);
    manifest.Save();
    Timer timer;
    run();
    const double seconds = timer.Seconds();
    manifest.Record(name, fingerprint, outputs, seconds);
    manifest.Save();
    std::cerr << "[" << index << "/" << total << "] " << name << ": done in " << seconds
              << " s\n";
  }
};

bool IsImageExtension(std::string ext) {
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".tif" ||
         ext == ".tiff" || ext == ".bmp" || ext == ".ppm" || ext == ".pgm";
}

// Matches the images of `database` with `type` (exhaustive, or sequential with loop
// closure: SequentialPairs through COLMAP's matches_importer). Pairs already matched in
// the database are not matched again.
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

struct MappedModel {
  std::string path;  // the largest model COLMAP's mapper made
  int registered = 0;
};

// Runs COLMAP's mapper into `out` and picks the model with most registered images
// (COLMAP numbers models by discovery, not size).
MappedModel MapLargestModel(const PrepareContext& c, const std::string& database,
                            const std::string& out, const std::string& threads) {
  colmap::CreateDirectories(out);
  colmap::RunColmap({"mapper", "--database_path", database, "--image_path", c.image_path,
                     "--output_path", out, "--Mapper.num_threads", threads});
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

// W/fvs/registration.json: how many of the photos SfM registered, which not, and how
// they were matched.
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

// Registered of total photos, and a warning for each held-out photo SfM did not
// register: it has no pose, so it cannot be a target (view_synthesis_eval skips it).
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

}  // namespace

std::set<std::string> ParseHoldoutList(const std::string& spec) {
  std::set<std::string> names;
  if (spec.empty()) return names;
  std::error_code ec;
  if (fs::is_regular_file(spec, ec)) {
    std::istringstream lines(ReadFileToString(spec));
    std::string line;
    while (std::getline(lines, line)) {
      line = TrimString(line);
      if (!line.empty() && line[0] != '#') names.insert(line);
    }
    return names;
  }
  for (const std::string& part : SplitString(spec, ",")) {
    const std::string name = TrimString(part);
    if (!name.empty()) names.insert(name);
  }
  return names;
}

std::vector<std::string> ListImageFiles(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error(folder, "image folder does not exist");
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.is_regular_file() && IsImageExtension(entry.path().extension().string())) {
      names.push_back(entry.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  if (names.empty())
    throw Error(folder, "no images (.jpg, .png, .tif, ...) in this folder");
  return names;
}

bool LooksLikeVideoFrames(const std::vector<std::string>& names) {
  if (names.size() < 10) return false;
  // Strip the extension and the trailing digits: all the same prefix, numbers
  // consecutive.
  std::string prefix;
  long last = -1;
  int consecutive = 0;
  for (size_t i = 0; i < names.size(); ++i) {
    std::string stem = fs::path(names[i]).stem().string();
    size_t d = stem.size();
    while (d > 0 && std::isdigit(static_cast<unsigned char>(stem[d - 1]))) --d;
    if (d == stem.size()) return false;
    const std::string p = stem.substr(0, d);
    const long n = std::stol(stem.substr(d, 15));
    if (i == 0) prefix = p;
    if (p != prefix) return false;
    if (last >= 0 && n == last + 1) ++consecutive;
    last = n;
  }
  return consecutive >= static_cast<int>(names.size() * 9 / 10);
}

MatcherChoice ChooseMatcher(const std::vector<std::string>& names, bool gpu) {
  const size_t n = names.size();
  const size_t limit = gpu ? kMaxExhaustiveImagesGpu : kMaxExhaustiveImages;
  const std::string count = std::to_string(n) + " images";
  if (n <= limit) {
    return {"exhaustive",
            count + ", at most " + std::to_string(limit) + ": every pair is matched"};
  }
  if (LooksLikeVideoFrames(names)) {
    return {"sequential", count + " numbered as consecutive video frames, over " +
                              std::to_string(limit) + ": sequential with loop closure"};
  }
  return {"exhaustive",
          count + " over " + std::to_string(limit) +
              ", not consecutive frames: every pair is matched (" +
              std::to_string(n * (n - 1) / 2) +
              " pairs; --Matching.type sequential is far cheaper for video frames)"};
}

std::vector<std::pair<int, int>> SequentialPairs(int n, int overlap) {
  std::set<std::pair<int, int>> pairs;
  if (n < 2) return {};
  for (int i = 0; i < n; ++i) {
    for (int k = 1; k <= overlap && i + k < n; ++k) pairs.insert({i, i + k});
    int step = 1;
    for (int k = 0; k < overlap && i + step < n; ++k, step *= 2)
      pairs.insert({i, i + step});
  }
  const int every = std::max(5, (n + 49) / 50);
  std::vector<int> keyframes;
  for (int i = 0; i < n; i += every) keyframes.push_back(i);
  if (keyframes.back() != n - 1) keyframes.push_back(n - 1);
  for (size_t a = 0; a < keyframes.size(); ++a) {
    for (size_t b = a + 1; b < keyframes.size(); ++b) {
      pairs.insert({keyframes[a], keyframes[b]});
    }
  }
  return {pairs.begin(), pairs.end()};
}

bool ShouldRetryExhaustive(const std::string& matcher, int registered, int total) {
  return matcher != "exhaustive" && registered < total;
}

void WriteStereoConfigs(const std::string& workspace_path,
                        const std::set<std::string>& holdout, int max_sources) {
  const colmap::DenseWorkspace ws(workspace_path);
  const colmap::Reconstruction rec = colmap::ReadSparseModel(ws.SparseDir());
  // Shared 3D points between image pairs rank the sources, as COLMAP's __auto__ does.
  std::map<uint32_t, std::map<uint32_t, int>> shared;
  for (const auto& [id, point] : rec.points3D) {
    std::set<uint32_t> images;
    for (const auto& el : point.track) images.insert(el.image_id);
    for (uint32_t a : images) {
      for (uint32_t b : images) {
        if (a != b) ++shared[a][b];
      }
    }
  }
  std::ostringstream patch_match, fusion;
  for (const auto& [id, image] : rec.images) {
    if (holdout.count(image.name)) continue;
    std::vector<std::pair<int, uint32_t>> ranked;
    for (const auto& [other, count] : shared[id]) {
      if (!holdout.count(rec.images.at(other).name)) ranked.push_back({-count, other});
    }
    std::sort(ranked.begin(), ranked.end());
    if (ranked.empty()) continue;  // sees nothing in common: no depth map possible
    patch_match << image.name << "\n";
    for (size_t i = 0; i < ranked.size() && static_cast<int>(i) < max_sources; ++i) {
      patch_match << (i ? ", " : "") << rec.images.at(ranked[i].second).name;
    }
    patch_match << "\n";
    fusion << image.name << "\n";
  }
  colmap::CreateDirectories(ws.StereoDir());
  WriteFileAtomic(ws.StereoDir() + "/patch-match.cfg",
                  [&](std::ostream& out) { out << patch_match.str(); });
  WriteFileAtomic(ws.StereoDir() + "/fusion.cfg",
                  [&](std::ostream& out) { out << fusion.str(); });
}

std::vector<std::string> ShrunkenUndistortionWarnings(
    const colmap::Reconstruction& sfm, const colmap::Reconstruction& undistorted,
    int max_image_size) {
  std::vector<std::string> warnings;
  for (const auto& [id, camera] : undistorted.cameras) {
    const auto it = sfm.cameras.find(id);
    if (it == sfm.cameras.end()) continue;
    const double before =
        static_cast<double>(std::max(it->second.width, it->second.height));
    const double expected =
        max_image_size > 0 ? std::min<double>(before, max_image_size) : before;
    const double after = static_cast<double>(std::max(camera.width, camera.height));
    if (expected > 0 && after < 0.5 * expected) {
      warnings.push_back(
          "undistortion shrank camera " + std::to_string(id) + " from " +
          std::to_string(it->second.width) + "x" + std::to_string(it->second.height) +
          " to " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
          ": its distortion estimate cannot be undone at the image borders; try "
          "--ImageReader.camera_model OPENCV (or PINHOLE for undistorted photos)");
    }
  }
  return warnings;
}

void RunPrepareStages(const PrepareContext& c) {
  const std::vector<std::string> images = ListImageFiles(c.image_path);
  for (const std::string& name : c.holdout) {
    if (!std::binary_search(images.begin(), images.end(), name)) {
      throw Error(c.image_path, "holdout image '" + name + "' is not in this folder");
    }
  }
  if (images.size() < 3) {
    throw Error(c.image_path, "only " + std::to_string(images.size()) +
                                  " images: view synthesis needs at least 3 photos");
  }
  // COLMAP skips a photo it cannot read and aborts later (an empty file made its matcher
  // fail a CHECK): every photo's header is read here, before the workspace is touched.
  for (const std::string& name : images) {
    int width = 0, height = 0;
    colmap::ReadImageSize(JoinPaths(c.image_path, name), &width, &height);
  }
  const colmap::DenseWorkspace ws(c.workspace_path);
  const std::string fvs_dir = ws.FvsDir();
  const std::string tmp_dir = fvs_dir + "/tmp";
  colmap::CreateDirectories(fvs_dir);
  RemoveAll(tmp_dir);  // leftovers of a killed run: never trusted
  colmap::CreateDirectories(tmp_dir);

  const colmap::ColmapCapabilities& colmap_caps = colmap::ProbeColmap();
  const std::string threads = std::to_string(c.num_threads);
  const std::string database = c.workspace_path + "/database.db";
  const std::string sfm_model = c.workspace_path + "/sfm/0";

  std::string matcher = c.matcher;
  std::string matcher_reason = "--Matching.type " + matcher;
  if (matcher == "auto") {
    const MatcherChoice choice = ChooseMatcher(images, colmap_caps.has_cuda);
    matcher = choice.type;
    matcher_reason = choice.reason;
  }
  const bool builtin_stereo = c.stereo_backend == "builtin" ||
                              (c.stereo_backend == "auto" && !colmap_caps.has_cuda);
  const bool builtin_mesher = c.mesher_backend == "builtin" ||
                              (c.mesher_backend == "auto" && !colmap_caps.has_cgal);
  if (c.stereo_backend == "colmap" && !colmap_caps.has_cuda) {
    throw Error(kWho, "--Stereo.backend colmap needs a COLMAP built with CUDA; " +
                          colmap_caps.executable + " has none (use builtin or auto)");
  }
  if (c.mesher_backend == "colmap" && !colmap_caps.has_cgal) {
    throw Error(kWho, "--Mesher.backend colmap needs a COLMAP built with CGAL; " +
                          colmap_caps.executable + " has none (use builtin or auto)");
  }
  std::string holdout_list;
  for (const std::string& h : c.holdout) holdout_list += h + ",";

  StageRunner stages;
  stages.manifest = Manifest::Load(ws.ManifestPath(), c.workspace_path);
  stages.total = 8;
  const std::string gpu = colmap_caps.has_cuda ? "1" : "0";

  stages.Run(
      "feature_extraction", {c.image_path},
      c.camera_model + " single=" + std::to_string(c.single_camera) +
          " size=" + std::to_string(c.max_image_size),
      {database}, [&] {
        // A database left by a killed extraction is incomplete: start over.
        const std::string tmp_db = tmp_dir + "/database.db";
        colmap::RunColmap(
            {"feature_extractor", "--database_path", tmp_db, "--image_path", c.image_path,
             "--ImageReader.camera_model", c.camera_model, "--ImageReader.single_camera",
             c.single_camera ? "1" : "0", "--SiftExtraction.use_gpu", gpu,
             "--SiftExtraction.max_image_size", std::to_string(c.max_image_size),
             "--SiftExtraction.num_threads", threads});
        MoveIntoPlace(tmp_db, database);
      });

  // Matching writes into the database: work on a copy, so a kill leaves what was there
  // untouched.
  auto match_into_database = [&](const std::string& type) {
    const std::string tmp_db = tmp_dir + "/database.db";
    fs::copy_file(database, tmp_db, fs::copy_options::overwrite_existing);
    RunMatcher(type, tmp_db, images, tmp_dir + "/pairs.txt", gpu, threads);
    MoveIntoPlace(tmp_db, database);
  };
  stages.Run("matching", {}, matcher, {database}, [&] {
    std::cerr << "  " << matcher << " matching: " << matcher_reason << "\n";
    match_into_database(matcher);
  });

  const std::string registration_path = fvs_dir + "/registration.json";
  stages.Run("mapping", {}, "", {sfm_model}, [&] {
    const int total = static_cast<int>(images.size());
    MappedModel best = MapLargestModel(c, database, tmp_dir + "/sfm", threads);
    const bool retry = ShouldRetryExhaustive(matcher, best.registered, total);
    if (retry) {
      std::cerr << "  registered " << best.registered << " of " << total
                << " images after " << matcher
                << " matching: matching every pair and mapping again\n";
      match_into_database("exhaustive");
      const MappedModel second =
          MapLargestModel(c, database, tmp_dir + "/sfm_exhaustive", threads);
      if (second.registered > best.registered) best = second;
    }
    if (best.path.empty() || best.registered < 3) {
      throw Error(c.image_path, "SfM registered " + std::to_string(best.registered) +
                                    " of " + std::to_string(total) +
                                    " images: too few for view synthesis (photos need "
                                    "more overlap and texture)");
    }
    std::cerr << "  registered " << best.registered << " of " << total << " images\n";
    WriteRegistrationReport(registration_path, images, best.path, matcher, retry);
    colmap::CreateDirectories(c.workspace_path + "/sfm");
    MoveIntoPlace(best.path, sfm_model);
  });
  // Workspaces prepared before the report existed.
  if (!fs::exists(registration_path)) {
    WriteRegistrationReport(registration_path, images, sfm_model, matcher, false);
  }

  stages.Run("undistortion", {},
             "size=" + std::to_string(c.max_image_size) + " holdout=" + holdout_list,
             {ws.ImagesDir(), ws.SparseDir()}, [&] {
               const std::string out = tmp_dir + "/undistorted";
               colmap::CreateDirectories(out);
               colmap::RunColmap({"image_undistorter", "--image_path", c.image_path,
                                  "--input_path", sfm_model, "--output_path", out,
                                  "--output_type", "COLMAP", "--max_image_size",
                                  std::to_string(c.max_image_size)});
               const colmap::Reconstruction rec =
                   colmap::ReadSparseModel(out + "/sparse");
               for (const std::string& w : ShrunkenUndistortionWarnings(
                        colmap::ReadSparseModel(sfm_model), rec, c.max_image_size)) {
                 std::cerr << "WARNING: " << w << "\n";
               }
               colmap::CreateDirectories(ws.StereoDir());
               MoveIntoPlace(out + "/images", ws.ImagesDir());
               MoveIntoPlace(out + "/sparse", ws.SparseDir());
               WriteStereoConfigs(c.workspace_path, c.holdout);
               WriteFileAtomic(fvs_dir + "/holdout.txt", [&](std::ostream& o) {
                 for (const std::string& h : c.holdout) o << h << "\n";
               });
             });

  const std::string depth_dir = ws.StereoDir() + "/depth_maps";
  stages.Run(
      "stereo", {},
      std::string(builtin_stereo ? "builtin" : "colmap") +
          " size=" + std::to_string(c.stereo_max_image_size),
      {depth_dir}, [&] {
        if (builtin_stereo) {
          std::vector<std::string> args = {"--workspace_path", c.workspace_path};
          if (c.stereo_max_image_size > 0) {
            args.push_back("--PatchMatchStereo.max_image_size");
            args.push_back(std::to_string(c.stereo_max_image_size));
          }
          RunOurCommand("view_synthesis_stereo", args);
        } else {
          colmap::RunColmap(
              {"patch_match_stereo", "--workspace_path", c.workspace_path,
               "--workspace_format", "COLMAP", "--PatchMatchStereo.geom_consistency", "1",
               "--PatchMatchStereo.max_image_size",
               std::to_string(c.stereo_max_image_size > 0 ? c.stereo_max_image_size
                                                          : -1)});
        }
      });

  stages.Run("fusion", {}, "", {ws.FusedPath(), ws.FusedVisPath()}, [&] {
    const std::string out = tmp_dir + "/fused.ply";
    colmap::RunColmap({"stereo_fusion", "--workspace_path", c.workspace_path,
                       "--workspace_format", "COLMAP", "--input_type", "geometric",
                       "--output_path", out, "--StereoFusion.num_threads", threads});
    std::error_code ec;
    if (!fs::exists(out, ec) || fs::file_size(out, ec) < 300) {
      throw Error(ws.FusedPath(),
                  "stereo fusion produced no points (the depth maps are "
                  "empty: too little texture or overlap?)");
    }
    MoveIntoPlace(out + ".vis", ws.FusedVisPath());
    MoveIntoPlace(out, ws.FusedPath());
  });

  stages.Run(
      "meshing", {}, builtin_mesher ? "builtin" : "colmap", {ws.DelaunayMeshPath()}, [&] {
        if (builtin_mesher) {
          RunOurCommand("view_synthesis_mesher", {"--workspace_path", c.workspace_path});
        } else {
          const std::string out = tmp_dir + "/meshed-delaunay.ply";
          colmap::RunColmap({"delaunay_mesher", "--input_path", c.workspace_path,
                             "--input_type", "dense", "--output_path", out});
          MoveIntoPlace(out, ws.DelaunayMeshPath());
        }
      });

  stages.Run("depth_cache", {}, "", {ws.FvsDir() + "/depth"}, [&] {
    RunOurCommand("view_synthesis_depth_cache", {"--workspace_path", c.workspace_path});
  });
  RemoveAll(tmp_dir);
  ReportRegistration(registration_path, c.holdout);
  std::cerr << "Scene ready: " << c.workspace_path << "\n";
}

}  // namespace fvs
