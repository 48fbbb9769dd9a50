// Target selection of the protocols, summaries with their Pareto front, and the CSV that
// shards are merged from (round trip, n/a kept, malformed files named with their line).
#include "fvs/eval/report.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fvs/eval/protocol.h"
#include "fvs/eval/sweep.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs::eval {
namespace {

std::vector<std::string> Names(int n) {
  std::vector<std::string> names;
  for (int i = n - 1; i >= 0; --i)
    names.push_back("img_" + std::to_string(10 + i) + ".png");
  return names;  // reverse order: the protocols sort by name
}

std::vector<std::string> TargetNames(const TargetSet& set) {
  std::vector<std::string> names;
  for (const EvalTarget& t : set.targets) names.push_back(t.name);
  return names;
}

TEST(Protocol, LeaveOneOutEveryNth) {
  ProtocolOptions o;
  o.protocol = "leave_one_out";
  o.every = 3;
  const TargetSet set = SelectTargets(Names(8), {"img_13.png"}, o);
  EXPECT_EQ(TargetNames(set),
            (std::vector<std::string>{"img_10.png", "img_13.png", "img_16.png"}));
  EXPECT_TRUE(set.excluded_sources.empty());  // each target only excludes itself
  EXPECT_TRUE(set.targets[1].geometry_holdout);
  EXPECT_FALSE(set.targets[0].geometry_holdout);
}

TEST(Protocol, AutoPicksHoldoutWhenThereIsOne) {
  ProtocolOptions o;
  EXPECT_EQ(SelectTargets(Names(4), {}, o).protocol, "leave_one_out");
  const TargetSet set = SelectTargets(Names(4), {"img_12.png", "img_11.png"}, o);
  EXPECT_EQ(set.protocol, "holdout");
  EXPECT_EQ(TargetNames(set), (std::vector<std::string>{"img_11.png", "img_12.png"}));
  EXPECT_EQ(set.excluded_sources.size(), 2u);
  o.protocol = "holdout";
  EXPECT_THROW(SelectTargets(Names(4), {}, o), Error);
}

// A held-out image SfM did not register (prepare warned) is a skipped target with the
// reason: not a failure, not counted in the summary, "skipped" in results.csv.
TEST(Protocol, UnregisteredHoldoutIsSkippedWithTheReason) {
  const TargetSet set = SelectTargets(Names(4), {"img_12.png", "lost.png"}, {});
  ASSERT_EQ(TargetNames(set), (std::vector<std::string>{"img_12.png", "lost.png"}));
  EXPECT_FALSE(set.targets[0].skipped);
  EXPECT_TRUE(set.targets[0].error.empty());
  EXPECT_TRUE(set.targets[1].skipped);
  EXPECT_NE(set.targets[1].error.find("not registered by SfM"), std::string::npos);

  ViewResult skipped;
  skipped.target = "lost.png";
  skipped.skipped = true;
  skipped.error = set.targets[1].error;
  ViewResult ok = skipped;
  ok.target = "img_12.png";
  ok.skipped = false;
  ok.error.clear();
  ok.psnr = 20;
  ok.ssim = 0.5;
  ok.seconds = 1;
  EXPECT_FALSE(skipped.ok());
  EXPECT_FALSE(skipped.failed());
  const std::vector<ConfigSummary> summary = Summarize({ok, skipped});
  ASSERT_EQ(summary.size(), 1u);
  EXPECT_EQ(summary[0].views_ok, 1);
  EXPECT_EQ(summary[0].views_failed, 0);
  testing::TempDir dir;
  WriteResultsCsv(dir / "results.csv", {ok, skipped});
  EXPECT_NE(testing::ReadTextFile(dir / "results.csv").find(",skipped,"),
            std::string::npos);
  const std::vector<ViewResult> back = ReadResultsCsv(dir / "results.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_TRUE(back[1].skipped);
  EXPECT_EQ(back[1].error, skipped.error);
  EXPECT_FALSE(back[0].skipped);
}

TEST(Protocol, SubsequenceIsWithheldAsAWhole) {
  ProtocolOptions o;
  o.protocol = "subsequence";
  o.subsequence = "2:3";
  const TargetSet set = SelectTargets(Names(8), {}, o);
  EXPECT_EQ(TargetNames(set),
            (std::vector<std::string>{"img_12.png", "img_13.png", "img_14.png"}));
  EXPECT_EQ(set.excluded_sources,
            (std::set<std::string>{"img_12.png", "img_13.png", "img_14.png"}));
  o.subsequence = "9:2";
  EXPECT_THROW(SelectTargets(Names(8), {}, o), Error);
  o.subsequence = "2-3";
  EXPECT_THROW(o.Check(), Error);
}

TEST(Protocol, IndicesKeepUnknownTargetsWithAnError) {
  ProtocolOptions o;
  o.protocol = "indices";
  o.target_indices = "0, 5,20";
  o.target_names = "img_11.png,nope.png";
  const TargetSet set = SelectTargets(Names(8), {}, o);
  ASSERT_EQ(set.targets.size(), 5u);
  EXPECT_EQ(set.targets[0].name, "img_10.png");
  EXPECT_EQ(set.targets[1].name, "img_15.png");
  EXPECT_NE(set.targets[2].error.find("past the 8 registered images"), std::string::npos);
  EXPECT_TRUE(set.targets[3].error.empty());
  EXPECT_NE(set.targets[4].error.find("not a registered image"), std::string::npos);
  EXPECT_EQ(set.excluded_sources.size(), 3u);  // only the ones that exist
  o.target_indices = "1,x";
  EXPECT_THROW(o.Check(), Error);
  o.target_indices = o.target_names = "";
  EXPECT_THROW(o.Check(), Error);
}

ViewResult Row(const std::string& method, int k, const std::string& target, double psnr,
               double seconds) {
  ViewResult r;
  r.scene = "room";
  r.config.method = method;
  r.config.num_sources = k;
  r.protocol = "leave_one_out";
  r.target = target;
  r.psnr = psnr;
  r.ssim = 0.5;
  r.seconds = seconds;
  r.sources_used = k;
  r.coverage = 1;
  r.width = 8;
  r.height = 6;
  return r;
}

TEST(Report, SummaryMeansAndParetoFront) {
  std::vector<ViewResult> rows = {
      Row("ulr", 1, "a", 20, 0.1),      Row("ulr", 1, "b", 22, 0.3),  // 21 dB, 0.2 s
      Row("ulr", 4, "a", 25, 0.4),      Row("ulr", 4, "b", 25, 0.4),  // 25 dB, 0.4 s
      Row("nearest", 1, "a", 18, 0.05), Row("nearest", 1, "b", 18, 0.05),
      Row("slow", 2, "a", 24, 1.0),     Row("slow", 2, "b", 24, 1.0)};  // dominated
  rows.push_back(Row("slow", 2, "c", 0, 0));
  rows.back().error = "broken";
  const std::vector<ConfigSummary> s = Summarize(rows);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_DOUBLE_EQ(s[0].psnr, 21);
  EXPECT_DOUBLE_EQ(s[0].seconds, 0.2);
  EXPECT_TRUE(s[0].pareto);
  EXPECT_TRUE(s[1].pareto);
  EXPECT_TRUE(s[2].pareto);
  EXPECT_FALSE(s[3].pareto);
  EXPECT_EQ(s[3].views_ok, 2);
  EXPECT_EQ(s[3].views_failed, 1);
  EXPECT_TRUE(std::isnan(s[0].lpips));  // no view had LPIPS: not available, not 0
}

TEST(Report, CsvRoundTripKeepsNotAvailableAndErrors) {
  testing::TempDir dir;
  std::vector<ViewResult> rows = {Row("ulr", 5, "dir/a b.png", 23.456789, 0.25),
                                  Row("ulr", 0, "x,\"y\".png", 0, 0)};
  rows[0].lpips = 0.123456;
  rows[0].config.scale = 0.5;
  rows[0].geometry_holdout = true;
  rows[0].mesh_pixels = 0.625;
  rows[0].infinity_pixels = 0.25;
  rows[0].filled_pixels = 0.125;
  rows[0].filled_seen_pixels = 0.0625;
  rows[1].error = "images/x.png: image is 4x4 but its camera is 8x6, \"bad\"";
  rows[1].psnr = rows[1].ssim = rows[1].seconds = rows[1].coverage = kNotAvailable;
  WriteResultsCsv(dir / "results.csv", rows);
  const std::vector<ViewResult> back = ReadResultsCsv(dir / "results.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].target, "dir/a b.png");
  EXPECT_NEAR(back[0].psnr, 23.4568, 1e-9);
  EXPECT_NEAR(back[0].lpips, 0.12346, 1e-9);
  EXPECT_DOUBLE_EQ(back[0].config.scale, 0.5);
  EXPECT_TRUE(back[0].geometry_holdout);
  EXPECT_EQ(back[0].config.Label(), rows[0].config.Label());
  EXPECT_DOUBLE_EQ(back[0].mesh_pixels, 0.625);
  EXPECT_DOUBLE_EQ(back[0].infinity_pixels, 0.25);
  EXPECT_DOUBLE_EQ(back[0].filled_pixels, 0.125);
  EXPECT_DOUBLE_EQ(back[0].filled_seen_pixels, 0.0625);
  EXPECT_TRUE(std::isnan(back[1].infinity_pixels));
  EXPECT_EQ(back[1].target, rows[1].target);
  EXPECT_EQ(back[1].error, rows[1].error);
  EXPECT_EQ(back[1].config.num_sources, 0);  // adaptive K, "auto" in the file
  EXPECT_FALSE(back[1].ok());
  EXPECT_TRUE(std::isnan(back[1].psnr));
  EXPECT_NE(testing::ReadTextFile(dir / "results.csv").find(",n/a,"), std::string::npos);

  std::string text = testing::ReadTextFile(dir / "results.csv");
  text.replace(text.find("23.4568"), 7, "23.4x68");
  testing::WriteTextFile(dir / "bad.csv", text);
  try {
    ReadResultsCsv(dir / "bad.csv");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2"), std::string::npos) << e.what();
  }
  testing::WriteTextFile(dir / "other.csv", "a,b\n1,2\n");
  EXPECT_THROW(ReadResultsCsv(dir / "other.csv"), Error);
}

// Files written before the pixel-origin columns (mesh, infinity, filled) still merge:
// those three read as n/a.
TEST(Report, ReadsResultsWithoutThePixelOriginColumns) {
  testing::TempDir dir;
  testing::WriteTextFile(
      dir / "old.csv",
      "scene,method,num_sources,scale,precision,protocol,target,geometry_holdout,status,"
      "psnr,ssim,lpips,psnr_covered,ssim_covered,seconds,cpu_seconds,sources_used,"
      "coverage,width,height,error\n"
      "room,ulr,5,1,fp32,leave_one_out,a.png,no,ok,23.5,0.8,n/a,25,0.85,0.2,0.4,5,0.9,"
      "8,6,\n");
  const std::vector<ViewResult> rows = ReadResultsCsv(dir / "old.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_DOUBLE_EQ(rows[0].coverage, 0.9);
  EXPECT_EQ(rows[0].width, 8);
  EXPECT_EQ(rows[0].height, 6);
  EXPECT_TRUE(std::isnan(rows[0].mesh_pixels));
  EXPECT_TRUE(std::isnan(rows[0].filled_pixels));
  EXPECT_TRUE(std::isnan(rows[0].filled_seen_pixels));

  // Written after the pixel-origin columns but before filled_seen_pixels.
  testing::WriteTextFile(
      dir / "mid.csv",
      "scene,method,num_sources,scale,precision,protocol,target,geometry_holdout,status,"
      "psnr,ssim,lpips,psnr_covered,ssim_covered,seconds,cpu_seconds,sources_used,"
      "coverage,mesh_pixels,infinity_pixels,filled_pixels,width,height,error\n"
      "room,ulr,5,1,fp32,leave_one_out,a.png,no,ok,23.5,0.8,n/a,25,0.85,0.2,0.4,5,0.9,"
      "0.5,0.25,0.125,8,6,\n");
  const std::vector<ViewResult> mid = ReadResultsCsv(dir / "mid.csv");
  ASSERT_EQ(mid.size(), 1u);
  EXPECT_DOUBLE_EQ(mid[0].filled_pixels, 0.125);
  EXPECT_EQ(mid[0].width, 8);
  EXPECT_TRUE(std::isnan(mid[0].filled_seen_pixels));
}

TEST(Sweep, PlansEveryCombinationAndSkipsNetworksWithoutWeights) {
  SweepOptions o;
  o.methods = "nearest,ulr,fvs_fast";
  o.num_sources = "1,3";
  o.scales = "1,0.5";
  const SweepPlan plan = PlanSweep(o);
  ASSERT_EQ(plan.configs.size(), 2u + 4u);  // nearest: K = 1 only
  EXPECT_EQ(plan.configs[0].Label(), "nearest K=1 s=1");
  EXPECT_EQ(plan.configs[5].Label(), "ulr K=3 s=0.5");
  EXPECT_EQ(plan.configs[5].Slug(), "ulr_k3_s0p5");
  ASSERT_EQ(plan.notes.size(), 1u);
  EXPECT_NE(plan.notes[0].find("fvs_fast: skipped"), std::string::npos);
  o.num_sources = "0";  // the adaptive K is spelled "auto" in lists and tables
  EXPECT_THROW(PlanSweep(o), Error);
  o.num_sources = "3,auto";
  const SweepPlan adaptive = PlanSweep(o);
  ASSERT_EQ(adaptive.configs.size(), 2u + 4u);
  EXPECT_EQ(adaptive.configs[3].num_sources, 0);
  EXPECT_EQ(adaptive.configs[3].Label(), "ulr K=auto s=1");
  EXPECT_EQ(adaptive.configs[3].Slug(), "ulr_kauto_s1");
  EXPECT_EQ(ParseNumSources(FormatNumSources(0), "t"), 0);
  EXPECT_EQ(ParseNumSources(FormatNumSources(7), "t"), 7);
  EXPECT_THROW(ParseNumSources("-2", "t"), Error);
  EXPECT_THROW(ParseNumSources("5x", "t"), Error);
  o.num_sources = "1";
  o.precisions = "fp8";
  EXPECT_THROW(PlanSweep(o), Error);
  // Other precisions are for the networks: the classical methods run once, in fp32.
  o.precisions = "fp32,bf16";
  const SweepPlan mixed = PlanSweep(o);
  ASSERT_EQ(mixed.configs.size(), 2u + 2u);
  for (const EvalConfig& c : mixed.configs) EXPECT_EQ(c.precision, "fp32");
  o.precisions = "fp16";  // and nothing else to run
  EXPECT_THROW(PlanSweep(o), Error);
}

}  // namespace
}  // namespace fvs::eval
