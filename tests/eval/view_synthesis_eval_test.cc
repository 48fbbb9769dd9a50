// `colmap view_synthesis_eval` and `view_synthesis_eval_merge` through the front door
// (FrontDoorBinary()) on a workspace written by the test from an exact mesh: the reports
// and their numbers, LPIPS reported as not available, bad input (a photo of the wrong
// size, a target not in the model) beside views that are still evaluated, shards that
// merge into the unsharded result, a small sweep with its Pareto table and plot, and
// LPIPS weights taken from FVS_LPIPS_PATH unless --lpips_path names others.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "colmap_ext/image_io.h"
#include "fvs/eval/report.h"
#include "net/lpips_fixture.h"
#include "scene/scene_fixture.h"
#include "scene/arc_workspace_test.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::FrontDoorBinary;
using testing::ReadTextFile;
using testing::RunShell;
namespace fs = std::filesystem;

class ViewSynthesisEvalTest : public testing::ArcWorkspaceTest {
 protected:
  ViewSynthesisEvalTest() : ArcWorkspaceTest(7, 80, 60) {}
  // `lpips_env`: the value of FVS_LPIPS_PATH for the run; unset when empty, so that a
  // shell's default does not change the reports.
  int Eval(const std::string& args, const std::string& out, std::string* output,
           const std::string& lpips_env = "") {
    const std::string env = lpips_env.empty() ? "env -u FVS_LPIPS_PATH "
                                              : "env FVS_LPIPS_PATH=" + lpips_env + " ";
    return RunShell(env + "FVS_QUIET=1 FVS_NUM_THREADS=2 " + FrontDoorBinary() +
                        " view_synthesis_eval --workspace_path " + ws_ +
                        " --output_path " + out + " " + args,
                    output);
  }
  static std::map<std::string, eval::ViewResult> ByTarget(const std::string& csv) {
    std::map<std::string, eval::ViewResult> rows;
    for (const eval::ViewResult& r : eval::ReadResultsCsv(csv)) rows[r.target] = r;
    return rows;
  }
};

TEST_F(ViewSynthesisEvalTest, LeaveOneOutReportsAndShardsMerge) {
  const std::string out = dir_ / "full";
  std::string output;
  ASSERT_EQ(Eval("--protocol leave_one_out --every 2 --method ulr --num_sources 3", out,
                 &output),
            0)
      << output;
  const auto rows = ByTarget(out + "/results.csv");
  ASSERT_EQ(rows.size(), 4u);  // positions 0, 2, 4, 6
  for (const auto& [name, r] : rows) {
    EXPECT_TRUE(r.ok()) << name << ": " << r.error;
    // An exact mesh and exact photos: the neighbours reproduce the view closely, except
    // at the ends of the arc where part of the view is seen by no other camera (black;
    // a black or unrelated image scores below 10 dB here).
    EXPECT_GT(r.psnr, 13.0) << name;
    EXPECT_GT(r.ssim, 0.5) << name;
    EXPECT_LE(r.ssim, 1.0) << name;
    EXPECT_GT(r.seconds, 0.0) << name;
    EXPECT_EQ(r.sources_used, 3) << name;
    EXPECT_TRUE(std::isnan(r.lpips)) << name;  // no weights: not available
    EXPECT_EQ(r.width, 80);
    // The closed test room: every pixel has a surface, none comes from infinity.
    EXPECT_NEAR(r.mesh_pixels + r.infinity_pixels + r.filled_pixels, 1.0, 2e-4) << name;
    EXPECT_NEAR(r.mesh_pixels, r.coverage, 2e-4) << name;
    EXPECT_EQ(r.infinity_pixels, 0.0) << name;
    // What no used source covered but another allowed one sees is part of the filled.
    EXPECT_GE(r.filled_seen_pixels, 0.0) << name;
    EXPECT_LE(r.filled_seen_pixels, r.filled_pixels + 1e-4) << name;
  }
  EXPECT_GT(rows.at("view_002.png").psnr, 25.0);  // inside the arc
  EXPECT_GT(rows.at("view_004.png").psnr, 25.0);
  const std::string md = ReadTextFile(out + "/results.md");
  EXPECT_NE(md.find("LPIPS: not available"), std::string::npos);
  EXPECT_NE(md.find("machine: nproc"), std::string::npos);
  EXPECT_NE(md.find("| view_004.png |"), std::string::npos);
  EXPECT_NE(ReadTextFile(out + "/summary.csv").find("ulr,3,1,fp32,4,0,"),
            std::string::npos);
  int w = 0, h = 0;
  colmap::ReadImageSize(out + "/contact_sheet.png", &w, &h);
  EXPECT_GE(w, 2 * 80);
  EXPECT_GE(h, 4 * 60);
  EXPECT_NE(output.find("s/view"), std::string::npos);  // time printed beside quality

  // Two shards cover the same targets, and merge into the same numbers.
  std::string shard_output;
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(Eval("--protocol leave_one_out --every 2 --method ulr --num_sources 3 "
                   "--shard " +
                       std::to_string(i) + "/2",
                   dir_ / ("shard" + std::to_string(i)), &shard_output),
              0)
        << shard_output;
  }
  EXPECT_EQ(ByTarget(dir_ / "shard0/results.csv").size(), 2u);
  const std::string merged = dir_ / "merged";
  ASSERT_EQ(RunShell(FrontDoorBinary() + " view_synthesis_eval_merge --input_paths " +
                         (dir_ / "shard0") + "," + (dir_ / "shard1") + " --output_path " +
                         merged,
                     &output),
            0)
      << output;
  const auto merged_rows = ByTarget(merged + "/results.csv");
  ASSERT_EQ(merged_rows.size(), rows.size());
  for (const auto& [name, r] : rows) {
    EXPECT_DOUBLE_EQ(merged_rows.at(name).psnr, r.psnr) << name;
    EXPECT_DOUBLE_EQ(merged_rows.at(name).ssim, r.ssim) << name;
  }
  EXPECT_TRUE(fs::exists(merged + "/contact_sheet.png"));
  EXPECT_TRUE(fs::exists(merged + "/results.md"));
  // The same shard twice is an error, and nothing is written.
  EXPECT_NE(RunShell(FrontDoorBinary() + " view_synthesis_eval_merge --input_paths " +
                         (dir_ / "shard0") + "," + (dir_ / "shard0") + " --output_path " +
                         (dir_ / "twice"),
                     &output),
            0);
  EXPECT_NE(output.find("overlapping shards"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir_ / "twice/results.csv"));
}

TEST_F(ViewSynthesisEvalTest, BadViewsAreReportedAndTheOthersEvaluated) {
  // view_003's photo has the wrong size; "missing.png" is not in the model; no LPIPS
  // weights where they were promised.
  colmap::WriteImage(ws_ + "/images/view_003.png", Image(40, 30, 3, 0.5f));
  const std::string out = dir_ / "bad";
  std::string output;
  EXPECT_NE(Eval("--protocol indices --target_indices 1,3,5 --target_names missing.png "
                 "--lpips_path " +
                     (dir_ / "no_such_lpips.safetensors"),
                 out, &output),
            0);
  EXPECT_NE(output.find("ERROR: " + out + "/results.csv: 2 of 4 view evaluations failed"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("no_such_lpips.safetensors"), std::string::npos) << output;
  const auto rows = ByTarget(out + "/results.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_TRUE(rows.at("view_001.png").ok());
  EXPECT_TRUE(rows.at("view_005.png").ok());
  EXPECT_GT(rows.at("view_005.png").psnr, 15.0);
  EXPECT_NE(rows.at("view_003.png").error.find("view_003.png: image is 40x30"),
            std::string::npos)
      << rows.at("view_003.png").error;
  EXPECT_NE(rows.at("missing.png").error.find("not a registered image"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(out + "/contact_sheet.png"));
  EXPECT_NE(ReadTextFile(out + "/results.md").find("LPIPS: not available"),
            std::string::npos);

  // Unusable options fail at once, with one line.
  EXPECT_NE(Eval("--shard 2/2", dir_ / "x", &output), 0);
  EXPECT_NE(output.find("--shard"), std::string::npos) << output;
  EXPECT_NE(Eval("--method fvs", dir_ / "x", &output), 0);
  EXPECT_NE(output.find("--model_path"), std::string::npos) << output;
}

TEST_F(ViewSynthesisEvalTest, LpipsWeightsFromTheEnvironmentUnlessTheFlagNamesOthers) {
  const std::string weights =
      testing::WriteRandomLpips(dir_ / "lpips_alex.safetensors", "alex");
  const std::string args = "--protocol indices --target_indices 3 --method ulr";
  std::string output;
  // The environment alone.
  ASSERT_EQ(Eval(args, dir_ / "env", &output, weights), 0) << output;
  auto rows = ByTarget(dir_ / "env/results.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_GT(rows.at("view_003.png").lpips, 0.0);
  EXPECT_NE(
      ReadTextFile(dir_ / "env/results.md").find("LPIPS v0.1 (alex) from " + weights),
      std::string::npos);
  // The flag wins over an environment that names no file.
  ASSERT_EQ(Eval(args + " --lpips_path " + weights, dir_ / "flag", &output,
                 dir_ / "no_such_lpips.safetensors"),
            0)
      << output;
  rows = ByTarget(dir_ / "flag/results.csv");
  EXPECT_GT(rows.at("view_003.png").lpips, 0.0);
  EXPECT_EQ(output.find("no_such_lpips"), std::string::npos) << output;
}

TEST_F(ViewSynthesisEvalTest, SweepWritesParetoTableAndPlot) {
  const std::string out = dir_ / "sweep";
  std::string output;
  ASSERT_EQ(Eval("--protocol subsequence --subsequence 2:2 --sweep 1 --sweep_methods "
                 "nearest,ulr,fvs_fast --sweep_num_sources 1,4 --sweep_scales 1,0.5",
                 out, &output),
            0)
      << output;
  const std::string summary = ReadTextFile(out + "/summary.csv");
  // nearest at two scales + ulr at 2 K x 2 scales; fvs_fast skipped (no weights).
  int lines = 0;
  for (char c : summary) lines += c == '\n';
  EXPECT_EQ(lines, 1 + 6) << summary;
  EXPECT_NE(summary.find(",yes\n"), std::string::npos) << summary;  // a Pareto front
  EXPECT_NE(ReadTextFile(out + "/results.md").find("fvs_fast: skipped"),
            std::string::npos);
  int w = 0, h = 0;
  colmap::ReadImageSize(out + "/error_vs_time.png", &w, &h);
  EXPECT_EQ(w, 960);
  // With the whole subsequence withheld, ulr with 4 sources beats the single nearest.
  std::map<std::string, double> psnr;
  for (const eval::ConfigSummary& s :
       eval::Summarize(eval::ReadResultsCsv(out + "/results.csv"))) {
    psnr[s.config.Label()] = s.psnr;
  }
  EXPECT_GT(psnr.at("ulr K=4 s=1"), psnr.at("nearest K=1 s=1"));
  EXPECT_GT(psnr.at("ulr K=4 s=1"), psnr.at("ulr K=4 s=0.5"));  // resolution costs
}

}  // namespace
}  // namespace fvs
