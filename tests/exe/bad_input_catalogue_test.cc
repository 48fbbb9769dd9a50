// The bad-input catalogue (issue 18, item 3), through the real front door: every command
// that reads user files, given a broken copy of a small generated fixture (truncated and
// mis-sized files, wrong magic, NaN/Inf poses, an unknown camera model, missing or
// zero-sized photos, mismatched weights, an empty camera path, a full disk, an output
// folder that cannot be created). For each case the rule is checked strictly:
//   - the exit status is 1 (an error return, not a signal or an abort);
//   - stderr is exactly one line (FVS_QUIET=1 silences progress, so nothing else may
//     appear there: no warnings, no stage logs), it starts with "ERROR: ", names the file
//     and says what is wrong (the case's words);
//   - no regular file under the case folder (inputs and outputs) is new, changed or
//     removed: nothing half-written, no temporary file left behind. A new, empty folder
//     is tolerated (it holds nothing a later run could mistake for output).
// The table below is the catalogue; doc/reliability.md lists it with the expected lines.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "colmap_ext/image_io.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/safetensors.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

namespace fs = std::filesystem;

// One bad input: `setup` breaks the fixture copies in the case folder, `args` follow
// `colmap` (run in the case folder, so paths are relative), the single error line must
// contain `file` and every one of `fault`.
struct BadInputCase {
  std::string name;
  std::function<void(const std::string& dir)> setup;
  std::string args;
  std::string file;
  std::vector<std::string> fault;
  // >= 0: run under `ulimit -f` this many blocks (a full disk); /bin/sh counts 512-byte
  // blocks.
  int file_size_limit_blocks = -1;
};

// --- Ways to break a file -------------------------------------------------------------

void Truncate(const std::string& path, uintmax_t size) { fs::resize_file(path, size); }

void PatchBytes(const std::string& path, std::streamoff offset,
                const std::string& bytes) {
  std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
  f.seekp(offset);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!f) throw std::runtime_error("cannot patch " + path);
}

// Little-endian bytes of a double (the sparse model's poses).
std::string DoubleBytes(double value) {
  std::string bytes(sizeof(double), '\0');
  std::memcpy(bytes.data(), &value, sizeof(double));
  return bytes;
}

void EditJson(const std::string& path, const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json json = nlohmann::json::parse(ReadTextFile(path));
  edit(json);
  WriteTextFile(path, json.dump(2));
}

// A real 10 x 10 PNG: decodable, the wrong size for everything here (64 x 48).
void WriteSmallPng(const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  Image image(10, 10, 3);
  for (float& v : image.data) v = 0.5f;
  colmap::WriteImage(path, image);
}

// A safetensors file with a colmap-fvs config of `variant` (or none) and one tensor that
// no network has: valid as a file, wrong as weights.
void WriteMismatchedWeights(const std::string& path, const std::string& variant) {
  SafeTensorsFile file;
  if (!variant.empty()) {
    file.metadata["fvs_config"] = nlohmann::json({{"variant", variant}}).dump();
  }
  const float one = 1.0f;
  file.Add(SafeTensor::FromFloats("bogus.weight", {1}, &one));
  WriteSafeTensors(path, file);
}

// The folder a path must not be created under when running as root (chmod does not stop
// root): a regular file "F" in the way makes F/... uncreatable for every user.
void MakeBlockingFile(const std::string& dir) { WriteTextFile(dir + "/F", "a file\n"); }

// --- The fixture, generated once ------------------------------------------------------
//   W/          4 views of 64 x 48 with the proxy mesh (view_synthesis_synthetic)
//   T/          W packed at scale 1 (view_synthesis_pack), list.txt names it
//   E/          view_synthesis_eval of W (results.csv, contact_sheet.png, ...)
//   path.json   a camera path through W (view_synthesis_path)

std::string Colmap() {
  return "FVS_QUIET=1 OMP_WAIT_POLICY=PASSIVE QT_QPA_PLATFORM=offscreen '" +
         FrontDoorBinary() + "'";
}

class BadInputCatalogue : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fixture_ = new TempDir;
    const std::string d = fixture_->path();
    const std::string c = "cd '" + d + "' && " + Colmap();
    std::string log;
    ASSERT_EQ(RunShell(c + " view_synthesis_synthetic --output_path W"
                           " --SyntheticScene.num_views 4 --SyntheticScene.width 64"
                           " --SyntheticScene.height 48"
                           " --SyntheticScene.write_proxy_mesh 1",
                       &log),
              0)
        << log;
    // The depth cache first (the others would race to write it), then three at once.
    ASSERT_EQ(RunShell(c + " view_synthesis_depth_cache --workspace_path W", &log), 0)
        << log;
    RunShell("cd '" + d + "' && (" + Colmap() +
                 " view_synthesis_pack --workspace_path W --output_path T --scale 1 & " +
                 Colmap() + " view_synthesis_eval --workspace_path W --output_path E & " +
                 Colmap() +
                 " view_synthesis_path --workspace_path W --output_path path.json"
                 " --duration 0.3 --fps 10 & wait)",
             &log);
    for (const char* f : {"T/scene.safetensors", "E/results.csv", "path.json"}) {
      ASSERT_TRUE(fs::is_regular_file(d + "/" + f)) << f << " not generated:\n" << log;
    }
  }
  static void TearDownTestSuite() {
    delete fixture_;
    fixture_ = nullptr;
  }
  static TempDir* fixture_;
};

TempDir* BadInputCatalogue::fixture_ = nullptr;

// Every regular file below `root` (relative name -> size and modification time).
std::map<std::string, std::pair<uintmax_t, int64_t>> Snapshot(const std::string& root) {
  std::map<std::string, std::pair<uintmax_t, int64_t>> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    files[fs::relative(entry.path(), root).string()] = {
        entry.file_size(), entry.last_write_time().time_since_epoch().count()};
  }
  return files;
}

std::vector<BadInputCase> Catalogue() {
  const std::string vs = "view_synthesis --workspace_path W --output_path O";
  const std::string interpolate = vs + " --interpolate 1";
  const std::string train =
      "view_synthesis_train --scene_list list.txt --output_path M --Train.max_steps 1"
      " --Train.num_sources 2";
  auto no_setup = [](const std::string&) {};
  // images.bin: number of images (8 bytes), then image 1: id (4), qvec (4 doubles),
  // tvec (3 doubles). cameras.bin: count (8), camera 1: id (4), model id (4), ...
  const std::streamoff qvec_w = 12, tvec_x = 12 + 4 * 8, camera_model = 12;
  return {
      // view_synthesis: the workspace.
      {"cameras_bin_truncated",
       [](const std::string& d) { Truncate(d + "/W/sparse/cameras.bin", 20); },
       interpolate,
       "W/sparse/cameras.bin",
       {"truncated"}},
      {"unknown_camera_model",
       [=](const std::string& d) {
         PatchBytes(d + "/W/sparse/cameras.bin", camera_model, std::string("\x63", 1));
       },
       interpolate,
       "W/sparse/cameras.bin",
       {"unknown camera model id 99"}},
      {"images_bin_wrong_count",
       [](const std::string& d) {
         PatchBytes(d + "/W/sparse/images.bin", 0, std::string("\xff\xff\xff\xff", 4));
       },
       interpolate,
       "W/sparse/images.bin",
       {"number of images is 4294967295", "truncated"}},
      {"pose_nan",
       [=](const std::string& d) {
         PatchBytes(d + "/W/sparse/images.bin", qvec_w, DoubleBytes(std::nan("")));
       },
       interpolate,
       "W/sparse/images.bin",
       {"frame_0000.png", "non-finite pose"}},
      {"pose_inf",
       [=](const std::string& d) {
         PatchBytes(d + "/W/sparse/images.bin", tvec_x, DoubleBytes(HUGE_VAL));
       },
       interpolate,
       "W/sparse/images.bin",
       {"non-finite pose"}},
      {"points3d_bin_truncated",
       [](const std::string& d) { Truncate(d + "/W/sparse/points3D.bin", 10); },
       interpolate,
       "W/sparse/points3D.bin",
       {"truncated"}},
      {"sparse_model_empty",
       [](const std::string& d) {
         for (const char* f : {"cameras.bin", "images.bin", "points3D.bin"}) {
           fs::remove(d + "/W/sparse/" + f);
         }
       },
       interpolate,
       "W/sparse",
       {"no sparse model"}},
      {"mesh_wrong_magic",
       [](const std::string& d) { PatchBytes(d + "/W/meshed-delaunay.ply", 0, "plx"); },
       interpolate,
       "W/meshed-delaunay.ply",
       {"not a PLY file", "wrong magic"}},
      {"mesh_truncated",
       [](const std::string& d) { Truncate(d + "/W/meshed-delaunay.ply", 300); },
       interpolate,
       "W/meshed-delaunay.ply",
       {"truncated"}},
      {"photo_missing",
       [](const std::string& d) { fs::remove(d + "/W/images/frame_0001.png"); },
       interpolate,
       "W/images/frame_0001.png",
       {"cannot read image"}},
      {"photo_zero_sized",
       [](const std::string& d) { Truncate(d + "/W/images/frame_0002.png", 0); },
       interpolate,
       "W/images/frame_0002.png",
       {"cannot read image"}},
      {"photo_wrong_size",
       [](const std::string& d) { WriteSmallPng(d + "/W/images/frame_0003.png"); },
       interpolate,
       "W/images/frame_0003.png",
       {"image is 10x10 but its camera is 64x48"}},
      // view_synthesis: camera paths, weights, ground truth, output.
      {"camera_path_no_frames",
       [](const std::string& d) {
         EditJson(d + "/path.json", [](nlohmann::json& j) {
           j["camera_path"] = nlohmann::json::array();
           j["keyframes"] = nlohmann::json::array();
         });
       },
       vs + " --camera_path path.json",
       "path.json",
       {"camera_path is empty"}},
      {"camera_path_matrix_wrong_size",
       [](const std::string& d) {
         EditJson(d + "/path.json", [](nlohmann::json& j) {
           j["camera_path"][0]["camera_to_world"].erase(0);
         });
       },
       vs + " --camera_path path.json",
       "path.json",
       {"16 (or 12) numbers"}},
      {"camera_path_truncated",
       [](const std::string& d) { Truncate(d + "/path.json", 200); },
       vs + " --camera_path path.json",
       "path.json",
       {"not valid JSON"}},
      {"camera_path_infinite_pose",
       [](const std::string& d) {
         // JSON has no NaN or Inf: a number past double's range is how one arrives.
         std::string text = ReadTextFile(d + "/path.json");
         const size_t at = text.find("\"camera_to_world\": [") + 20;
         text.insert(at, "1e999, ");
         WriteTextFile(d + "/path.json", text);
       },
       vs + " --camera_path path.json",
       "path.json",
       {"number overflow"}},
      {"weights_missing",
       no_setup,
       interpolate + " --method fvs --model_path nosuch.safetensors",
       "nosuch.safetensors",
       {"cannot open"}},
      {"weights_mismatched",
       [](const std::string& d) {
         WriteMismatchedWeights(d + "/w.safetensors", "fvs_fast");
       },
       interpolate + " --method fvs --model_path w.safetensors",
       "w.safetensors",
       {"weights do not match network variant 'fvs_fast'", "missing"}},
      {"weights_truncated",
       [](const std::string& d) {
         WriteMismatchedWeights(d + "/w.safetensors", "fvs_fast");
         Truncate(d + "/w.safetensors", 20);
       },
       interpolate + " --method fvs --model_path w.safetensors",
       "w.safetensors",
       {"truncated"}},
      {"ground_truth_wrong_size",
       [](const std::string& d) { WriteSmallPng(d + "/G/frame_00000.png"); },
       interpolate + " --ground_truth_path G",
       "G/frame_00000.png",
       {"ground truth of 10x10 for a frame of 64x48"}},
      {"output_folder_uncreatable",
       MakeBlockingFile,
       "view_synthesis --workspace_path W --output_path F/O --interpolate 1",
       "F/O",
       {"cannot create the output folder", "Not a directory"}},
      {"disk_full_render",
       no_setup,
       interpolate,
       "O/render_settings.json",
       {"write failed"},
       0},
      // view_synthesis_path.
      {"path_no_keyframes",
       [](const std::string& d) {
         EditJson(d + "/path.json", [](nlohmann::json& j) {
           j["camera_path"] = nlohmann::json::array();
           j["keyframes"] = nlohmann::json::array();
         });
       },
       "view_synthesis_path --workspace_path W --output_path P/out.json"
       " --keyframes_path path.json",
       "path.json",
       {"empty"}},
      {"path_unknown_keyframe",
       no_setup,
       "view_synthesis_path --workspace_path W --output_path P/out.json"
       " --keyframes frame_0000.png,nosuch.png",
       "nosuch.png",
       {"not a registered image"}},
      {"path_disk_full",
       no_setup,
       "view_synthesis_path --workspace_path W --output_path P/out.json",
       "P/out.json",
       {"write failed"},
       0},
      {"path_output_uncreatable",
       MakeBlockingFile,
       "view_synthesis_path --workspace_path W --output_path F/P/out.json",
       "F/P",
       {"cannot create the folder"}},
      // view_synthesis_pack.
      {"pack_disk_full",
       no_setup,
       "view_synthesis_pack --workspace_path W --output_path T2 --scale 1",
       "T2/scene.safetensors",
       {"write failed"},
       16},  // 8 KiB of the 87 KiB written
      {"pack_output_uncreatable",
       MakeBlockingFile,
       "view_synthesis_pack --workspace_path W --output_path F/T2 --scale 1",
       "F/T2",
       {"cannot create the output folder"}},
      // view_synthesis_eval.
      {"eval_weights_mismatched",
       [](const std::string& d) {
         WriteMismatchedWeights(d + "/w.safetensors", "fvs_fast");
       },
       "view_synthesis_eval --workspace_path W --output_path E2 --method fvs"
       " --model_path w.safetensors",
       "w.safetensors",
       {"weights do not match"}},
      {"eval_cameras_bin_truncated",
       [](const std::string& d) { Truncate(d + "/W/sparse/cameras.bin", 20); },
       "view_synthesis_eval --workspace_path W --output_path E2",
       "W/sparse/cameras.bin",
       {"truncated"}},
      {"eval_output_uncreatable",
       MakeBlockingFile,
       "view_synthesis_eval --workspace_path W --output_path F/E2",
       "F/E2",
       {"cannot create the output folder"}},
      // view_synthesis_eval_merge.
      {"merge_folder_without_results",
       [](const std::string& d) { fs::create_directories(d + "/X"); },
       "view_synthesis_eval_merge --input_paths E,X --output_path M",
       "X",
       {"no results.csv"}},
      {"merge_results_truncated",
       [](const std::string& d) { Truncate(d + "/E/results.csv", 250); },
       "view_synthesis_eval_merge --input_paths E --output_path M",
       "E/results.csv:2",
       {"fields, expected"}},
      {"merge_contact_sheet_wrong_magic",
       [](const std::string& d) { WriteTextFile(d + "/E/contact_sheet.png", "garbage"); },
       "view_synthesis_eval_merge --input_paths E --output_path M",
       "E/contact_sheet.png",
       {"cannot read image"}},
      {"merge_overlapping_shards",
       no_setup,
       "view_synthesis_eval_merge --input_paths E,E --output_path M",
       "E/results.csv",
       {"overlapping shards"}},
      {"merge_disk_full",
       no_setup,
       "view_synthesis_eval_merge --input_paths E --output_path M",
       "M/results.csv",
       {"write failed"},
       0},
      // view_synthesis_train.
      {"train_scene_missing",
       [](const std::string& d) { WriteTextFile(d + "/list.txt", d + "/nosuch\n"); },
       train,
       "list.txt",
       {"does not exist"}},
      {"train_scene_list_empty",
       [](const std::string& d) { WriteTextFile(d + "/list.txt", ""); },
       train,
       "list.txt",
       {"names no scene"}},
      {"train_pack_truncated",
       [](const std::string& d) { Truncate(d + "/T/scene.safetensors", 5000); },
       train,
       "T/scene.safetensors",
       {"truncated"}},
      {"train_pack_wrong_magic",
       [](const std::string& d) {
         WriteTextFile(d + "/T/scene.safetensors", "garbage!!");
       },
       train,
       "T/scene.safetensors",
       {"not a safetensors file"}},
      {"train_init_weights_mismatched",
       [](const std::string& d) {
         WriteMismatchedWeights(d + "/w.safetensors", "fvs_fast");
       },
       train + " --Train.init_weights w.safetensors",
       "w.safetensors",
       {"weights do not match"}},
      // view_synthesis_finetune: nothing may be written into W before the weights load.
      {"finetune_weights_missing",
       no_setup,
       "view_synthesis_finetune --workspace_path W --minutes 0.1"
       " --model_path nosuch.safetensors",
       "nosuch.safetensors",
       {"cannot open"}},
      {"finetune_weights_mismatched",
       [](const std::string& d) {
         WriteMismatchedWeights(d + "/w.safetensors", "fvs_fast");
       },
       "view_synthesis_finetune --workspace_path W --minutes 0.1 --method fvs_fast"
       " --model_path w.safetensors",
       "w.safetensors",
       {"weights do not match"}},
      // view_synthesis_model_info.
      {"model_info_weights_without_config",
       [](const std::string& d) { WriteMismatchedWeights(d + "/w.safetensors", ""); },
       "view_synthesis_model_info --weights w.safetensors --time 0",
       "w.safetensors",
       {"no network config"}},
      // view_synthesis_mesher.
      {"mesher_fused_missing",
       no_setup,
       "view_synthesis_mesher --workspace_path W --output_path W/out.ply",
       "W/fused.ply",
       {"missing"}},
      {"mesher_fused_wrong_magic",
       [](const std::string& d) {
         WriteTextFile(d + "/W/fused.ply", "garbage\n");
         WriteTextFile(d + "/W/fused.ply.vis", "x");
       },
       "view_synthesis_mesher --workspace_path W --output_path W/out.ply",
       "W/fused.ply",
       {"not a PLY file"}},
      // view_synthesis_stereo: the default configs are not written for a broken
      // workspace.
      {"stereo_photo_missing",
       [](const std::string& d) { fs::remove(d + "/W/images/frame_0001.png"); },
       "view_synthesis_stereo --workspace_path W",
       "W/images/frame_0001.png",
       {"image file is missing"}},
      {"stereo_config_unknown_image",
       [](const std::string& d) {
         fs::create_directories(d + "/W/stereo");
         WriteTextFile(d + "/W/stereo/patch-match.cfg", "nosuch.png\n__auto__, 3\n");
       },
       "view_synthesis_stereo --workspace_path W",
       "W/stereo/patch-match.cfg",
       {"'nosuch.png' is not in the sparse model"}},
      // view_synthesis_depth_cache.
      {"depth_cache_mesh_truncated",
       [](const std::string& d) { Truncate(d + "/W/meshed-delaunay.ply", 300); },
       "view_synthesis_depth_cache --workspace_path W",
       "W/meshed-delaunay.ply",
       {"truncated"}},
      // view_synthesis_refine: the mesh is read before anything is written into W.
      {"refine_mesh_truncated",
       [](const std::string& d) { Truncate(d + "/W/meshed-delaunay.ply", 300); },
       "view_synthesis_refine --workspace_path W --minutes 0.1",
       "W/meshed-delaunay.ply",
       {"truncated"}},
      {"depth_cache_disk_full",
       [](const std::string& d) { fs::remove_all(d + "/W/fvs/depth"); },
       "view_synthesis_depth_cache --workspace_path W",
       "W/fvs/depth/",
       {"write failed"},
       0},
      // view_synthesis_prepare: photo folders.
      {"prepare_empty_folder",
       [](const std::string& d) { fs::create_directories(d + "/P"); },
       "view_synthesis_prepare --image_path P --workspace_path WS",
       "P",
       {"no images"}},
      {"prepare_zero_sized_photos",
       [](const std::string& d) {
         fs::create_directories(d + "/P");
         for (const char* f : {"a.png", "b.png", "c.png"}) {
           WriteTextFile(d + "/P/" + f, "");
         }
       },
       "view_synthesis_prepare --image_path P --workspace_path WS",
       "P/a.png",
       {"cannot read image"}},
      {"prepare_heic_truncated",
       [](const std::string& d) {
         // Two good photos and a HEIC cut short (a phone's upload interrupted).
         fs::create_directories(d + "/P");
         fs::copy_file(d + "/W/images/frame_0000.png", d + "/P/a.png");
         fs::copy_file(d + "/W/images/frame_0001.png", d + "/P/b.png");
         if (RunShell("oiiotool '" + d + "/W/images/frame_0002.png' -o '" + d +
                      "/P/c.heic'") != 0) {
           throw std::runtime_error("oiiotool cannot write HEIC");
         }
         Truncate(d + "/P/c.heic", fs::file_size(d + "/P/c.heic") / 3);
       },
       "view_synthesis_prepare --image_path P --workspace_path WS",
       "P/c.heic",
       {"cannot read image"}},
      {"prepare_workspace_uncreatable",
       MakeBlockingFile,
       "view_synthesis_prepare --image_path W/images --workspace_path F/WS",
       "F/WS",
       {"cannot create"}},
      // view_synthesis_synthetic: ground truth of a camera path.
      {"synthetic_camera_path_no_frames",
       [](const std::string& d) {
         EditJson(d + "/path.json",
                  [](nlohmann::json& j) { j["camera_path"] = nlohmann::json::array(); });
       },
       "view_synthesis_synthetic --output_path S --camera_path path.json",
       "path.json",
       {"camera_path is empty"}},
  };
}

struct CaseResult {
  int status = -1;
  std::string stderr_text;
  std::vector<std::string> changes;  // files new, changed or removed
  std::string setup_error;
  double seconds = 0;
};

CaseResult RunCase(const BadInputCase& c, const std::string& fixture,
                   const std::string& root) {
  CaseResult r;
  const std::string dir = root + "/" + c.name;
  try {
    // cp -a: with their times, so that W's depth cache (keyed on the mesh's size and
    // time) stays current and a scene loads without writing anything.
    fs::create_directories(dir);
    std::string log;
    if (RunShell("cp -a '" + fixture + "'/W '" + fixture + "'/T '" + fixture + "'/E '" +
                     fixture + "'/path.json '" + dir + "'/",
                 &log) != 0) {
      throw std::runtime_error("cannot copy the fixture: " + log);
    }
    WriteTextFile(dir + "/list.txt", dir + "/T\n");
    c.setup(dir);
  } catch (const std::exception& e) {
    r.setup_error = e.what();
    return r;
  }
  const auto before = Snapshot(dir);
  // stderr through the pipe, not into a file: under `ulimit -f 0` a file could not take
  // the error line. In a subshell, since RunShell appends 2>&1 to the command line.
  std::string command = "(cd '" + dir + "' && ";
  if (c.file_size_limit_blocks >= 0) {
    command += "ulimit -f " + std::to_string(c.file_size_limit_blocks) + " && ";
  }
  // A child killed by a signal (an abort, SIGXFSZ) exits as 128 + n: not the 1 expected.
  command += "exec env FVS_QUIET=1 OMP_WAIT_POLICY=PASSIVE QT_QPA_PLATFORM=offscreen '" +
             FrontDoorBinary() + "' " + c.args + " 2>&1 >/dev/null)";
  const auto start = std::chrono::steady_clock::now();
  r.status = RunShell(command, &r.stderr_text);
  r.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto after = Snapshot(dir);
  for (const auto& [name, stat] : after) {
    const auto it = before.find(name);
    if (it == before.end()) {
      r.changes.push_back("new " + name);
    } else if (it->second != stat) {
      r.changes.push_back("changed " + name);
    }
  }
  for (const auto& [name, stat] : before) {
    if (!after.count(name)) r.changes.push_back("removed " + name);
  }
  return r;
}

TEST_F(BadInputCatalogue, EveryCaseIsOneErrorLineNamingTheFileAndLeavesNoOutput) {
  const std::vector<BadInputCase> cases = Catalogue();
  ASSERT_GE(cases.size(), 30u);
  TempDir root;
  // Two at a time: most of a case is the front door starting (loading LibTorch, COLMAP).
  std::vector<CaseResult> results(cases.size());
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < cases.size(); i = next++) {
      results[i] = RunCase(cases[i], fixture_->path(), root.path());
    }
  };
  std::thread other(worker);
  worker();
  other.join();

  for (size_t i = 0; i < cases.size(); ++i) {
    const BadInputCase& c = cases[i];
    const CaseResult& r = results[i];
    // The catalogue as run (doc/reliability.md): case | command | seconds | stderr.
    std::printf("| %s | `colmap %s` | %.1f | `%s` |\n", c.name.c_str(), c.args.c_str(),
                r.seconds, r.stderr_text.substr(0, r.stderr_text.find('\n')).c_str());
    SCOPED_TRACE("case " + c.name + ": colmap " + c.args + " (" +
                 std::to_string(r.seconds) + " s)");
    ASSERT_TRUE(r.setup_error.empty()) << r.setup_error;
    EXPECT_EQ(r.status, 1) << "stderr:\n" << r.stderr_text;
    const std::string& e = r.stderr_text;
    const size_t newline = e.find('\n');
    EXPECT_TRUE(!e.empty() && newline == e.size() - 1)
        << "stderr is not exactly one line:\n"
        << e;
    EXPECT_EQ(e.rfind("ERROR: ", 0), 0u) << e;
    EXPECT_NE(e.find(c.file), std::string::npos)
        << "does not name " << c.file << ": " << e;
    for (const std::string& words : c.fault) {
      EXPECT_NE(e.find(words), std::string::npos)
          << "does not say " << words << ": " << e;
    }
    std::string changes;
    for (const std::string& change : r.changes) changes += "  " + change + "\n";
    EXPECT_TRUE(r.changes.empty()) << "files left behind or touched:\n" << changes;
  }
}

// Issue 42, item 5: a workspace being written stops a second writer at once with one
// line naming the holder, lets readers go on, and is taken over after a kill -9. The
// holder is a second real process (forked here, holding the lock as prepare does); the
// contenders are the real front door.
TEST_F(BadInputCatalogue, AFolderBeingWrittenStopsASecondWriterAndLetsReadersGoOn) {
  TempDir root;
  const std::string dir = root.path();
  ASSERT_EQ(RunShell("cp -a '" + fixture_->path() + "'/W '" + dir + "'/"), 0);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t holder = ::fork();
  ASSERT_GE(holder, 0);
  if (holder == 0) {
    ::close(ready[0]);
    try {
      const FolderLock workspace(dir + "/W", "view_synthesis_prepare");
      const FolderLock frames(dir + "/O", "view_synthesis");
      if (::write(ready[1], "1", 1) != 1) ::_exit(2);
      while (true) ::pause();
    } catch (...) {
      ::_exit(3);
    }
  }
  ::close(ready[1]);
  char ok = 0;
  ASSERT_EQ(::read(ready[0], &ok, 1), 1);
  ::close(ready[0]);
  const std::string pid = std::to_string(holder);
  const auto before = Snapshot(dir + "/W");
  auto run = [&](const std::string& args, std::string* err) {
    // In a subshell: RunShell appends 2>&1, which would send stderr to /dev/null too.
    return RunShell("(cd '" + dir + "' && " + Colmap() + " " + args + " 2>&1 >/dev/null)",
                    err);
  };
  std::string err;
  for (const std::string args : {"view_synthesis_depth_cache --workspace_path W",
                                 "view_synthesis_mesher --workspace_path W",
                                 "view_synthesis_stereo --workspace_path W"}) {
    EXPECT_EQ(run(args, &err), 1) << args << ": " << err;
    EXPECT_EQ(err.rfind("ERROR: W: in use by colmap view_synthesis_prepare (process " +
                            pid + ", since ",
                        0),
              0u)
        << args << ": " << err;
    EXPECT_EQ(err.find('\n'), err.size() - 1) << "one line: " << err;
  }
  EXPECT_EQ(
      run("view_synthesis --workspace_path W --output_path O --interpolate 1", &err), 1);
  EXPECT_NE(err.find("ERROR: O: in use by colmap view_synthesis (process " + pid),
            std::string::npos)
      << err;
  EXPECT_EQ(before, Snapshot(dir + "/W")) << "a refused writer touched the workspace";
  // Readers of W writing elsewhere go on.
  EXPECT_EQ(
      run("view_synthesis --workspace_path W --output_path O2 --interpolate 1", &err), 0)
      << err;
  EXPECT_EQ(run("view_synthesis_eval --workspace_path W --output_path E2", &err), 0)
      << err;

  ::kill(holder, SIGKILL);
  ::waitpid(holder, nullptr, 0);
  EXPECT_EQ(run("view_synthesis_depth_cache --workspace_path W", &err), 0) << err;
  EXPECT_FALSE(fs::exists(dir + "/W/.colmap-fvs.lock")) << "taken over and released";
}

}  // namespace
}  // namespace fvs::testing
