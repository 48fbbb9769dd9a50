// Per-scene fine-tuning (train/finetune.h) on a small workspace written to disk: it
// publishes W/fvs/finetuned/<variant>.safetensors within its budget, a rerun with the
// same budget does nothing, a larger one trains on from the checkpoint, other starting
// weights start afresh, and photos held out at prepare never enter training.
#include "fvs/train/finetune.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fvs/net/net.h"
#include "fvs/scene/scene.h"
#include "fvs/train/data.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

nlohmann::json Card(const std::string& ws) {
  return nlohmann::json::parse(
      ReadFileToString(WorkspaceFinetunedModelDir(ws) + "/fvs_agg.json"));
}

FinetuneOptions SmallRun(const std::string& ws, double minutes) {
  FinetuneOptions o;
  o.workspace_path = ws;
  o.minutes = minutes;
  o.crop = 24;
  o.batch_size = 1;
  o.num_sources = 2;
  o.loss = "l1+ssim";
  o.quiet = true;
  return o;
}

TEST(FinetuneTest, PublishesWithinBudgetResumesAndKeepsHoldoutOut) {
  TempDir dir;
  const std::string ws = dir / "ws";
  testing::WriteTestWorkspace(ws, testing::ArcViews(5, 64, 48),
                              testing::MakeTestWorldMesh());
  const Scene scene = Scene::Load(ws);
  const std::string held = scene.view(2).name;
  WriteFileAtomic(ws + "/fvs/holdout.txt", [&](std::ostream& f) { f << held << "\n"; });

  FinetuneSummary first = RunFinetune(SmallRun(ws, 0.05));
  ASSERT_FALSE(first.interrupted);
  EXPECT_TRUE(first.init_path.empty());  // no generic weights given: the initial ones
  EXPECT_EQ(first.model_path, WorkspaceFinetunedModelDir(ws) + "/fvs_agg.safetensors");
  ASSERT_TRUE(fs::is_regular_file(first.model_path));
  EXPECT_GT(first.steps, 0);
  ModelConfig config;
  LoadModel(first.model_path, &config);
  EXPECT_EQ(config.variant, "fvs_agg");
  EXPECT_EQ(Card(ws)["finetune"]["steps"].get<int>(), first.steps);

  // The held-out photo is in the pack, marked, and never a target nor a source.
  const PackedScene pack = LoadPackedScene(ws + "/fvs/finetune/pack");
  int held_index = -1;
  for (int i = 0; i < pack.num_views(); ++i)
    if (pack.names[i] == held) held_index = i;
  ASSERT_GE(held_index, 0);
  EXPECT_TRUE(pack.holdout[held_index]);
  for (int t = 0; t < pack.num_views(); ++t) {
    for (int s : SelectTrainingSources(pack, t, 4)) EXPECT_NE(s, held_index);
  }

  // Same budget: nothing to do. A larger one: on from the checkpoint.
  const FinetuneSummary again = RunFinetune(SmallRun(ws, 0.05));
  EXPECT_EQ(again.steps, 0);
  EXPECT_EQ(Card(ws)["finetune"]["steps"].get<int>(), first.steps);
  const FinetuneSummary more = RunFinetune(SmallRun(ws, 0.1));
  EXPECT_GT(more.steps, first.steps);
  EXPECT_GT(more.train_seconds, first.train_seconds);

  // Other starting weights: the run starts afresh from them.
  const std::string generic = dir / "generic.safetensors";
  fs::copy_file(first.model_path, generic);
  FinetuneOptions from_generic = SmallRun(ws, 0.05);
  from_generic.model_path = generic;
  const FinetuneSummary fresh = RunFinetune(from_generic);
  EXPECT_GT(fresh.steps, 0);
  EXPECT_EQ(Card(ws)["finetune"]["init_weights"].get<std::string>(), generic);
}

TEST(FinetuneTest, BadInputIsOneClearError) {
  TempDir dir;
  FinetuneOptions o = SmallRun(dir / "missing", 1);
  EXPECT_THROW(RunFinetune(o), Error);
  o.workspace_path = dir.path();
  o.minutes = 0;
  EXPECT_THROW(RunFinetune(o), Error);
  o.minutes = 1;
  o.model_path = dir / "no_such.safetensors";
  EXPECT_THROW(RunFinetune(o), Error);
}

}  // namespace
}  // namespace fvs
