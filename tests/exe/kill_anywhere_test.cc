// Kill -9 anywhere (issue 18 item 4), through the front door: a render of a frame
// sequence, an evaluation and a training run are killed with SIGKILL at several points (after a few
// frames or checkpoints, and again part-way through the rerun), then run to the end. The
// final outputs must equal those of an uninterrupted run byte for byte (both are
// deterministic: the ulr renderer, and one-thread training from a seed; an evaluation's
// seconds per view are not, so its rows are compared without them), and the frames,
// views or steps finished before a kill are not done again. (view_synthesis_prepare's kill
// test is tests/exe/prepare_end_to_end_test.cc.)
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

namespace fs = std::filesystem;

std::string FrontDoor() {
  // No ffmpeg: the video step is skipped with a warning, the frames are what is compared.
  return "OMP_WAIT_POLICY=PASSIVE QT_QPA_PLATFORM=offscreen FVS_QUIET=1 "
         "FVS_FFMPEG=/nonexistent/ffmpeg '" +
         FrontDoorBinary() + "'";
}

// Runs `command` in the background and SIGKILLs it as soon as `path` exists (or when it
// ends by itself). Returns false when the command ended before `path` appeared.
bool KillWhenExists(const std::string& command, const std::string& path) {
  const std::string script =
      "(" + command + ") > /dev/null 2>&1 & pid=$!; " +
      "while kill -0 $pid 2>/dev/null; do " + "if [ -e '" + path +
      "' ]; then kill -9 $pid; " +
      "wait $pid 2>/dev/null; exit 0; fi; sleep 0.005; done; exit 1";
  return RunShell(script) == 0;
}

// The regular files under `dir` (relative paths) with their bytes, minus `skip` names.
std::map<std::string, std::string> FilesUnder(const std::string& dir,
                                              const std::vector<std::string>& skip) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (std::find(skip.begin(), skip.end(), name) != skip.end()) continue;
    files[fs::relative(e.path(), dir).string()] = ReadTextFile(e.path().string());
  }
  return files;
}

void ExpectSameFiles(const std::map<std::string, std::string>& expected,
                     const std::map<std::string, std::string>& actual) {
  for (const auto& [name, bytes] : actual) {
    EXPECT_TRUE(expected.count(name)) << name << " is left over";
  }
  ASSERT_EQ(expected.size(), actual.size());
  for (const auto& [name, bytes] : expected) {
    ASSERT_TRUE(actual.count(name)) << name << " is missing";
    EXPECT_TRUE(actual.at(name) == bytes) << name << " differs";
  }
}

TEST(KillAnywhere, KilledVideoRenderEndsWithTheUninterruptedFrames) {
  TempDir dir;
  WriteTestWorkspace(dir / "ws", ArcViews(4, 160, 120), MakeTestWorldMesh());
  auto render = [&](const std::string& out) {
    return FrontDoor() + " view_synthesis --workspace_path " + dir / "ws" +
           " --orbit 16 --method ulr --num_sources 2 --num_threads 1 --output_path " +
           out + " --video " + out + "/orbit.mp4";
  };
  std::string log;
  ASSERT_EQ(RunShell(render(dir / "straight") + " 2>&1", &log), 0) << log;
  const auto expected = FilesUnder(
      dir / "straight", {"frame_report.csv", "frame_report.json", "orbit.mp4"});
  ASSERT_GE(expected.size(), 16u);

  // Killed after the 3rd frame, the rerun killed after the 10th, then run to the end.
  const std::string killed = render(dir / "killed");
  ASSERT_TRUE(KillWhenExists(killed, dir / "killed/frame_00002.png")) << "ended too soon";
  ASSERT_TRUE(KillWhenExists(killed, dir / "killed/frame_00009.png")) << "ended too soon";
  ASSERT_EQ(RunShell(killed + " 2>&1", &log), 0) << log;
  ExpectSameFiles(
      expected,
      FilesUnder(dir / "killed", {"frame_report.csv", "frame_report.json", "orbit.mp4"}));
  // The last run rendered only what the kills had left undone (plus the frame before
  // the first missing one, which restores the temporal chain).
  const auto report =
      nlohmann::json::parse(ReadTextFile(dir / "killed/frame_report.json"));
  EXPECT_GE(report["num_resumed"].get<int>(), 9) << log;
  EXPECT_LE(report["num_rendered"].get<int>(), 7) << log;
}

// results.csv without its run-time columns (seconds, cpu_seconds): the rest of a row is
// deterministic. (No field of these rows holds a comma.)
std::string ResultsWithoutTimes(const std::string& path) {
  std::string text = ReadTextFile(path), out;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::stringstream line(text.substr(start, end - start));
    std::string field;
    for (int i = 0; std::getline(line, field, ','); ++i) {
      if (i != 14 && i != 15) out += field + ",";
    }
    out += "\n";
    start = end + 1;
  }
  return out;
}

TEST(KillAnywhere, KilledEvaluationEndsWithTheUninterruptedResults) {
  TempDir dir;
  WriteTestWorkspace(dir / "ws", ArcViews(12, 240, 180), MakeTestWorldMesh());
  auto evaluate = [&](const std::string& out) {
    return FrontDoor() + " view_synthesis_eval --workspace_path " + dir / "ws" +
           " --protocol leave_one_out --method ulr --num_sources 3 --num_threads 1"
           " --output_path " + out;
  };
  std::string log;
  ASSERT_EQ(RunShell("FVS_LPIPS_PATH= " + evaluate(dir / "straight") + " 2>&1", &log), 0)
      << log;
  ASSERT_TRUE(ResultsWithoutTimes(dir / "straight/results.csv").find("view_011.png") !=
              std::string::npos);

  // Killed after the 3rd view, the rerun killed after the 8th, then run to the end.
  const std::string killed = "FVS_LPIPS_PATH= " + evaluate(dir / "killed");
  const std::string journal = dir / "killed/views/ulr_k3_s1/";
  ASSERT_TRUE(KillWhenExists(killed, journal + "view_002.png.json")) << "ended too soon";
  ASSERT_TRUE(KillWhenExists(killed, journal + "view_007.png.json")) << "ended too soon";
  ASSERT_EQ(RunShell(killed + " 2>&1", &log), 0) << log;
  EXPECT_EQ(ResultsWithoutTimes(dir / "straight/results.csv"),
            ResultsWithoutTimes(dir / "killed/results.csv"));
  // The last run evaluated only what the kills had left undone.
  std::smatch resumed;
  ASSERT_TRUE(std::regex_search(log, resumed, std::regex("resuming: ([0-9]+) of 12")))
      << log;
  EXPECT_GE(std::stoi(resumed[1]), 8) << log;
  // Run once more, every view comes from the journal, seconds and thumbnails included:
  // the reports are those of the run before, byte for byte (the contact sheet's
  // captions hold the seconds, so the straight run's sheet differs).
  const auto reports = FilesUnder(dir / "killed", {"machine.txt"});
  ASSERT_EQ(RunShell(killed + " 2>&1", &log), 0) << log;
  EXPECT_NE(log.find("resuming: 12 of 12"), std::string::npos) << log;
  ExpectSameFiles(reports, FilesUnder(dir / "killed", {"machine.txt"}));

  // Other settings (here K) evaluate every view again; so does --overwrite 1.
  ASSERT_EQ(RunShell(FrontDoor() + " view_synthesis_eval --workspace_path " + dir / "ws" +
                         " --protocol leave_one_out --method ulr --num_sources 2"
                         " --num_threads 1 --output_path " + dir / "killed" + " 2>&1",
                     &log),
            0)
      << log;
  EXPECT_EQ(log.find("resuming:"), std::string::npos) << log;
  ASSERT_EQ(RunShell(killed + " --overwrite 1 2>&1", &log), 0) << log;
  EXPECT_EQ(log.find("resuming:"), std::string::npos) << log;
}

TEST(KillAnywhere, KilledTrainingEndsWithTheUninterruptedWeights) {
  TempDir dir;
  WriteTestWorkspace(dir / "ws", ArcViews(6, 64, 48), MakeTestWorldMesh());
  std::string log;
  ASSERT_EQ(RunShell(FrontDoor() + " view_synthesis_pack --workspace_path " + dir / "ws" +
                         " --output_path " + dir / "packed" + " --scale 1 2>&1",
                     &log),
            0)
      << log;
  WriteTextFile(dir / "train.txt", "packed\n");
  auto train = [&](const std::string& out) {
    return FrontDoor() + " view_synthesis_train --scene_list " + dir / "train.txt" +
           " --output_path " + out +
           " --Train.variant fvs_agg --Train.num_sources 2 --Train.crop 32"
           " --Train.batch_size 2 --Train.max_steps 12 --Train.checkpoint_every_steps 1"
           " --Train.keep_checkpoints 2 --Train.num_threads 1 --Train.loss l1+ssim"
           " --Train.log_every 4";
  };
  ASSERT_EQ(RunShell(train(dir / "straight") + " 2>&1", &log), 0) << log;
  const std::string killed = train(dir / "killed");
  ASSERT_TRUE(KillWhenExists(killed, dir / "killed/checkpoint-3.pt")) << "ended too soon";
  ASSERT_TRUE(KillWhenExists(killed, dir / "killed/checkpoint-8.pt")) << "ended too soon";
  ASSERT_EQ(RunShell(killed + " 2>&1", &log), 0) << log;
  // The last run went on from step 8 or later, not from the start.
  std::smatch start;
  ASSERT_TRUE(std::regex_search(log, start, std::regex("step ([0-9]+) -> 12"))) << log;
  EXPECT_GE(std::stoi(start[1]), 8) << log;
  EXPECT_EQ(ReadTextFile(dir / "straight/model.safetensors"),
            ReadTextFile(dir / "killed/model.safetensors"));
}

}  // namespace
}  // namespace fvs::testing
