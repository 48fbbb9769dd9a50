// Which weights a network method takes without --model_path: the scene's fine-tuned ones
// (W/fvs/finetuned, view_synthesis_finetune) before the shipped ones ($FVS_MODEL_DIR
// first among those), and none when neither exists.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "fvs/render/fvs_method.h"
#include "fvs/scene/scene.h"
#include "support/test_support.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;

void Touch(const fs::path& file) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << "x";
}

TEST(ModelPathTest, SceneWeightsComeBeforeShippedOnes) {
  testing::TempDir dir;
  const fs::path shipped = fs::path(dir.path()) / "models";
  const std::string ws = dir / "ws";
  const std::string scene_dir = WorkspaceFinetunedModelDir(ws);
  EXPECT_EQ(scene_dir, (fs::path(ws) / "fvs" / "finetuned").string());
  ASSERT_EQ(setenv("FVS_MODEL_DIR", shipped.c_str(), 1), 0);
  const std::string variant = "no_such_variant_but_files";
  bool is_scene = true;
  EXPECT_EQ(DefaultModelPath(variant, scene_dir, &is_scene), "");
  EXPECT_FALSE(is_scene);

  Touch(shipped / (variant + ".safetensors"));
  EXPECT_EQ(ShippedModelPath(variant), (shipped / (variant + ".safetensors")).string());
  EXPECT_EQ(DefaultModelPath(variant, scene_dir, &is_scene), ShippedModelPath(variant));
  EXPECT_FALSE(is_scene);

  Touch(fs::path(scene_dir) / (variant + ".safetensors"));
  EXPECT_EQ(DefaultModelPath(variant, scene_dir, &is_scene),
            (fs::path(scene_dir) / (variant + ".safetensors")).string());
  EXPECT_TRUE(is_scene);
  // No scene folder given (a render without a workspace): the shipped ones.
  EXPECT_EQ(DefaultModelPath(variant, "", &is_scene), ShippedModelPath(variant));
  EXPECT_FALSE(is_scene);
  unsetenv("FVS_MODEL_DIR");
}

}  // namespace
}  // namespace fvs
