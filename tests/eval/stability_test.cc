// The stability suite (view_synthesis_stability): every case renders without NaN or Inf
// and the same 10 km from the origin, with the classical methods and the network (random
// fvs_fast weights: stability does not need trained ones), in-process and through the
// front door (FrontDoorBinary()).
#include "fvs/eval/stability.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "fvs/net/net.h"
#include "support/test_support.h"

namespace fvs::eval {
namespace {

// A 40x30 suite with random fvs_fast weights saved in `dir`.
StabilityOptions WithRandomFastNetwork(const testing::TempDir& dir) {
  torch::manual_seed(3);
  const ModelConfig config = ModelConfig::ForVariant("fvs_fast");
  FvsNet net(config);
  StabilityOptions options;
  options.model_path = dir / "fvs_fast.safetensors";
  SaveWeights(net, config, options.model_path, /*fp16=*/false);
  options.width = 40;
  options.height = 30;
  return options;
}

TEST(Stability, EveryCaseIsFiniteAndTranslationInvariant) {
  testing::TempDir dir;
  StabilityOptions options = WithRandomFastNetwork(dir);
  options.methods = {"nearest", "ulr", "fvs_fast"};
  const std::vector<StabilityResult> results = RunStabilitySuite(options);
  ASSERT_EQ(results.size(), StabilityCaseNames().size() * 3);
  for (const StabilityResult& r : results) {
    const std::string what = r.case_name + " / " + r.method;
    EXPECT_TRUE(r.error.empty()) << what << ": " << r.error;
    EXPECT_EQ(r.nan_count, 0) << what;
    EXPECT_EQ(r.inf_count, 0) << what;
    EXPECT_LE(r.max_deviation, 1.0 / 255) << what;
    EXPECT_GT(r.seconds, 0.0) << what;
    if (r.case_name == "reference" || r.case_name == "k_too_large") {
      EXPECT_GT(r.covered, 0.5) << what;  // an ordinary view is mostly covered
    }
    if (r.case_name == "depth_0" || r.case_name == "behind_sources") {
      EXPECT_LT(r.covered, 0.05) << what;  // nothing there to take colour from
    }
  }
}

// The network's reduced-precision and tiled paths face the same extremes.
TEST(Stability, Bf16AndTilesStayFiniteAndTranslationInvariant) {
  testing::TempDir dir;
  StabilityOptions options = WithRandomFastNetwork(dir);
  options.methods = {"fvs_fast"};
  options.precision = "bf16";
  options.tile_size = 16;  // 3 x 2 tiles of 40x30
  for (const StabilityResult& r : RunStabilitySuite(options)) {
    EXPECT_TRUE(r.error.empty()) << r.case_name << ": " << r.error;
    EXPECT_EQ(r.nan_count + r.inf_count, 0) << r.case_name;
    EXPECT_LE(r.max_deviation, 1.0 / 255) << r.case_name;
  }
}

TEST(Stability, CommandPrintsTheTable) {
  testing::TempDir dir;
  std::string output;
  ASSERT_EQ(
      testing::RunShell("FVS_QUIET=1 " + testing::FrontDoorBinary() +
                            " view_synthesis_stability --methods nearest --width 32 "
                            "--height 24 --output_path " +
                            dir.path(),
                        &output),
      0)
      << output;
  for (const std::string& name : StabilityCaseNames()) {
    EXPECT_NE(output.find(name), std::string::npos) << output;
  }
  EXPECT_NE(output.find("max_dev_far"), std::string::npos) << output;
  EXPECT_NE(output.find("nproc"), std::string::npos) << output;
  EXPECT_NE(testing::ReadTextFile(dir / "stability.md").find("| depth_1e30 | nearest |"),
            std::string::npos);
}

}  // namespace
}  // namespace fvs::eval
