// The trainer end to end on a tiny packed scene and a tiny network: the loss goes down on
// a fixed sample, a resumed run is bit-identical to an uninterrupted one, a corrupt
// newest checkpoint falls back to the previous one, bad input gives clear errors, VGG19
// weights load by name, LPIPS weights make the loss L1 + LPIPS and add LPIPS columns to
// the validation.
#include "fvs/train/trainer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "fvs/net/net.h"
#include "fvs/train/data.h"
#include "fvs/train/loss.h"
#include "fvs/train/pack.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"
#include "net/lpips_fixture.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"
#include "train/tiny_net.h"

namespace fvs {
namespace {

using testing::TempDir;

using testing::kTinyNet;
using testing::kTinyNetNoSkip;

class TrainerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // The runs below choose their LPIPS weights themselves, whatever the shell says.
    ::unsetenv(kLpipsPathEnv);
    dir_ = new TempDir();
    const Scene scene = testing::MakeTestScene(6, 64, 48);
    PackOptions options;
    options.scale = 1.0;
    PackScene(scene, options, dir_->path() + "/scene_a");
    const Scene small = testing::MakeTestScene(3, 64, 48);
    PackScene(small, options, dir_->path() + "/scene_small");
    testing::WriteTextFile(dir_->path() + "/train.txt", "scene_a\n");
    testing::WriteTextFile(dir_->path() + "/val.txt", "scene_small\n");
  }
  static void TearDownTestSuite() { delete dir_; }

  static TrainOptions Options(const std::string& output) {
    TrainOptions o =
        testing::TinyTrainOptions(dir_->path() + "/train.txt", dir_->path() + "/" + output);
    o.max_steps = 4;
    o.log_every = 2;
    return o;
  }
  static TempDir* dir_;
};
TempDir* TrainerTest::dir_ = nullptr;

TEST_F(TrainerTest, LossDecreasesOnAFixedSample) {
  torch::set_num_threads(1);
  torch::manual_seed(0);
  const PackedScene scene = LoadPackedScene(dir_->path() + "/scene_a");
  SampleWarpOptions warp;
  warp.ulr_log_weights = true;  // the prior of fvs_fast
  const TrainingSample s =
      MakeSample(scene, 2, SelectTrainingSources(scene, 2, 2), 16, 8, 32, 32, warp);
  TrainingLoss loss(LossOptions{}, torch::kCPU);
  auto train = [&](const char* config, double* first, double* last) {
    FvsNet net(ModelConfig::FromJson(config));
    torch::optim::Adam adam(net->parameters(), torch::optim::AdamOptions(3e-3));
    for (int i = 0; i < 30; ++i) {
      adam.zero_grad();
      const BlendOutput out = net->Forward(s.source_rgb, s.warp.grid, s.warp.valid_depth,
                                           s.warp.valid_warp, s.warp.ulr_log_weights);
      LossValue l = loss((out.rgb + 1) * 0.5, s.target_rgb);
      l.total.backward();
      adam.step();
      (i == 0 ? *first : *last) = l.l1 + l.second;
    }
  };
  double first = 0, last = 0;
  train(kTinyNetNoSkip, &first, &last);
  EXPECT_TRUE(std::isfinite(last));
  EXPECT_LT(last, 0.7 * first) << "first " << first << " last " << last;
  // With the colour skip the untrained net already blends the sources: it starts far
  // lower and does not get worse.
  double skip_first = 0, skip_last = 0;
  train(kTinyNet, &skip_first, &skip_last);
  EXPECT_LT(skip_first, 0.5 * first) << skip_first << " vs " << first;
  EXPECT_LE(skip_last, skip_first * 1.05) << skip_first << " -> " << skip_last;
}

TEST_F(TrainerTest, SsimIsOneForEqualImagesAndLowerOtherwise) {
  const torch::Tensor a = torch::rand({1, 3, 20, 24});
  EXPECT_NEAR(Ssim(a, a).item<double>(), 1.0, 1e-5);
  EXPECT_LT(Ssim(a, torch::rand({1, 3, 20, 24})).item<double>(), 0.2);
  EXPECT_THROW(Ssim(torch::rand({1, 3, 8, 8}), torch::rand({1, 3, 8, 8})), Error);
}

TEST_F(TrainerTest, ResumedRunIsBitIdenticalToAnUninterruptedOne) {
  TrainOptions straight = Options("straight");
  straight.val_scene_list = dir_->path() + "/val.txt";
  straight.val_every = 2;
  straight.val_views = 2;
  const TrainSummary a = RunTraining(straight);
  EXPECT_EQ(a.steps_done, 4);
  EXPECT_EQ(a.resumed_from, -1);
  EXPECT_TRUE(std::isfinite(a.final_loss));

  TrainOptions first = Options("resumed");
  first.max_steps = 2;
  EXPECT_EQ(RunTraining(first).steps_done, 2);
  TrainOptions second = Options("resumed");
  const TrainSummary b = RunTraining(second);
  EXPECT_EQ(b.resumed_from, 2);
  EXPECT_EQ(b.steps_done, 4);

  const SafeTensorsFile wa = ReadSafeTensors(a.model_path);
  const SafeTensorsFile wb = ReadSafeTensors(b.model_path);
  ASSERT_EQ(wa.tensors.size(), wb.tensors.size());
  for (size_t i = 0; i < wa.tensors.size(); ++i) {
    EXPECT_EQ(wa.tensors[i].name, wb.tensors[i].name);
    EXPECT_TRUE(wa.tensors[i].data == wb.tensors[i].data) << wa.tensors[i].name;
  }
  // And the weights did move away from the initialisation (same seed, no steps).
  torch::manual_seed(0);
  const ModelConfig tiny = ModelConfig::FromJson(kTinyNet);
  FvsNet fresh(tiny);
  SaveWeights(fresh, tiny, dir_->path() + "/fresh.safetensors", false);
  const SafeTensorsFile w0 = ReadSafeTensors(dir_->path() + "/fresh.safetensors");
  int changed = 0;
  for (size_t i = 0; i < w0.tensors.size(); ++i)
    changed += w0.tensors[i].data != wa.tensors[i].data;
  EXPECT_GT(changed, 0);
  // Validation wrote its rows (two passes: step 2 and the end).
  const std::string csv = ReadFileToString(dir_->path() + "/straight/validation.csv");
  EXPECT_NE(
      csv.find("step,scene,views,psnr,ssim,seconds_per_view,ulr_psnr,ulr_ssim,lpips,"
               "ulr_lpips\n"),
      std::string::npos);
  EXPECT_NE(csv.find("\n2,all,2,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",n/a,n/a\n"), std::string::npos) << "no LPIPS weights: " << csv;
  EXPECT_NE(csv.find("\n4,all,2,"), std::string::npos) << csv;
  const std::string card = ReadFileToString(dir_->path() + "/straight/model.json");
  EXPECT_NE(card.find("\"validation\""), std::string::npos);
  EXPECT_NE(card.find("\"steps\": 4"), std::string::npos);
  EXPECT_NE(card.find("\"loss\": \"l1+ssim\""), std::string::npos) << card;
  // Only the newest two checkpoints are kept.
  const auto checkpoints = Trainer::ListCheckpoints(dir_->path() + "/straight");
  ASSERT_EQ(checkpoints.size(), 1u);  // a single one was written (at the end)
  EXPECT_EQ(checkpoints[0].first, 4);
  // The model loads through the net's own loader.
  ModelConfig config;
  FvsNet loaded = LoadModel(a.model_path, &config);
  EXPECT_EQ(config.ToJson(), ModelConfig::FromJson(kTinyNet).ToJson());
}

// M/best.safetensors follows the best validation (and its card says which step);
// --Train.init_weights starts from given weights; --Train.max_train_minutes stops the run
// with a model written.
TEST_F(TrainerTest, BestModelInitWeightsAndTimeBudget) {
  TrainOptions o = Options("best");
  o.val_scene_list = dir_->path() + "/val.txt";
  o.val_every = 1;
  o.val_views = 2;
  const TrainSummary a = RunTraining(o);
  ASSERT_TRUE(std::filesystem::is_regular_file(o.output_path + "/best.safetensors"));
  const nlohmann::json best =
      nlohmann::json::parse(ReadFileToString(o.output_path + "/best.json"));
  const int best_step = best.at("validation").at("step").get<int>();
  EXPECT_GE(best_step, 1);
  EXPECT_LE(best_step, a.steps_done);
  EXPECT_NE(ReadFileToString(o.output_path + "/validation.csv")
                .find("\n" + std::to_string(best_step) + ",all,"),
            std::string::npos);

  // Starting from weights: one step of a vanishing step size (Adam moves each weight by
  // about the step size) leaves exactly those weights; the budget stopped the run, a
  // model was written and its card names the weights.
  TrainOptions init = Options("init");
  init.init_weights = a.model_path;
  init.learning_rate = 1e-12;
  init.max_train_minutes = 1e-9;
  const TrainSummary b = RunTraining(init);
  EXPECT_EQ(b.steps_done, 1);
  ASSERT_FALSE(b.model_path.empty());
  ModelConfig config_a, config_b;
  FvsNet na = LoadModel(a.model_path, &config_a), nb = LoadModel(b.model_path, &config_b);
  EXPECT_EQ(config_a.ToJson(), config_b.ToJson());
  const auto pa = na->parameters(), pb = nb->parameters();
  ASSERT_EQ(pa.size(), pb.size());
  for (size_t i = 0; i < pa.size(); ++i)
    EXPECT_TRUE(torch::allclose(pa[i], pb[i], 0, 1e-6)) << i;
  EXPECT_NE(ReadFileToString(init.output_path + "/model.json").find("\"init_weights\""),
            std::string::npos);
  init.init_weights = dir_->path() + "/no_such.safetensors";
  init.output_path = dir_->path() + "/init_missing";
  EXPECT_THROW(RunTraining(init), Error);
}

// --Train.frozen: the parameters named keep their starting values exactly, the others
// train, the card says what was frozen, and a part no name contains is one clear error.
TEST_F(TrainerTest, FrozenParametersKeepTheirStartingValues) {
  const ModelConfig tiny = ModelConfig::FromJson(kTinyNet);
  FvsNet start(tiny);
  const std::string start_path = dir_->path() + "/frozen_start.safetensors";
  SaveWeights(start, tiny, start_path, false);
  TrainOptions o = Options("frozen");
  o.init_weights = start_path;
  o.frozen = "rgb_head, encoder_d0";
  o.learning_rate = 1e-2;
  const TrainSummary trained = RunTraining(o);
  ModelConfig config;
  FvsNet end = LoadModel(trained.model_path, &config);
  const auto a = start->named_parameters(), b = end->named_parameters();
  int frozen = 0, moved = 0;
  for (const auto& item : a) {
    const bool is_frozen = item.key().find("rgb_head") != std::string::npos ||
                           item.key().find("encoder_d0") != std::string::npos;
    const bool same = torch::equal(item.value(), b[item.key()]);
    if (is_frozen) {
      ++frozen;
      EXPECT_TRUE(same) << item.key();
    } else if (!same) {
      ++moved;
    }
  }
  EXPECT_GT(frozen, 0);
  EXPECT_GT(moved, 0);
  EXPECT_NE(ReadFileToString(o.output_path + "/model.json").find("\"frozen\""),
            std::string::npos);
  o.frozen = "no_such_module";
  o.output_path = dir_->path() + "/frozen_bad";
  try {
    RunTraining(o);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_module"), std::string::npos)
        << e.what();
  }
}

TEST_F(TrainerTest, CorruptNewestCheckpointFallsBackToThePrevious) {
  TrainOptions o = Options("corrupt");
  o.max_steps = 3;
  o.checkpoint_every_steps = 1;
  RunTraining(o);
  auto checkpoints = Trainer::ListCheckpoints(o.output_path);
  ASSERT_EQ(checkpoints.size(), 2u);  // keep_checkpoints = 2
  EXPECT_EQ(checkpoints[0].first, 3);
  EXPECT_EQ(checkpoints[1].first, 2);
  // Truncate the newest.
  const std::string bytes = ReadFileToString(checkpoints[0].second);
  {
    std::ofstream out(checkpoints[0].second, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), bytes.size() / 3);
  }
  {
    // A resumed run takes the command line's step size, not the one Adam saved.
    TrainOptions smaller = o;
    smaller.learning_rate = o.learning_rate / 4;
    Trainer trainer(smaller);
    EXPECT_EQ(trainer.resumed_from(), 2);
    EXPECT_EQ(trainer.step(), 2);
    EXPECT_DOUBLE_EQ(trainer.learning_rate(), o.learning_rate / 4);
  }
  // Both unusable: a clear error rather than a silent fresh start.
  {
    std::ofstream out(checkpoints[1].second, std::ios::binary | std::ios::trunc);
    out << "garbage";
  }
  try {
    Trainer trainer(o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no usable checkpoint"), std::string::npos)
        << e.what();
  }
}

TEST_F(TrainerTest, BadInputGivesClearErrors) {
  // Too few views for K sources (3 views, K = 5 needs 6).
  TrainOptions o = Options("bad");
  o.scene_list = dir_->path() + "/val.txt";
  o.num_sources = 5;
  try {
    Trainer trainer(o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("needs at least 6"), std::string::npos)
        << e.what();
  }
  // A missing scene, named with its line.
  testing::WriteTextFile(dir_->path() + "/bad.txt", "scene_a\nno_such_scene\n");
  o = Options("bad");
  o.scene_list = dir_->path() + "/bad.txt";
  try {
    Trainer trainer(o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
  }
  // A checkpoint of another network is refused, not mixed in.
  TrainOptions small = Options("other_net");
  small.max_steps = 1;
  RunTraining(small);
  TrainOptions other = Options("other_net");
  other.model_config_json.clear();
  other.variant = "fvs_fast";
  EXPECT_THROW(Trainer trainer(other), Error);
  // Option parsing.
  TrainOptions parsed;
  std::vector<std::string> args = {"prog",    "--scene_list",      "L", "--output_path",
                                   "M",       "--Train.max_steps", "7", "--Train.variant",
                                   "fvs_fast"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  EXPECT_TRUE(ParseTrainOptions(static_cast<int>(argv.size()), argv.data(), 1, &parsed));
  EXPECT_EQ(parsed.max_steps, 7);
  EXPECT_EQ(parsed.variant, "fvs_fast");
  args = {"prog", "--scene_list", "L", "--output_path", "M", "--Train.max_steps", "x"};
  argv.clear();
  for (auto& a : args) argv.push_back(a.data());
  EXPECT_THROW(ParseTrainOptions(static_cast<int>(argv.size()), argv.data(), 1, &parsed),
               Error);
  args = {"prog", "--output_path", "M"};
  argv.clear();
  for (auto& a : args) argv.push_back(a.data());
  EXPECT_THROW(ParseTrainOptions(static_cast<int>(argv.size()), argv.data(), 1, &parsed),
               Error);
}

TEST_F(TrainerTest, PerceptualLossLoadsVgg19ByName) {
  // Random weights under torchvision's names (real ones cannot be downloaded here).
  torch::manual_seed(1);
  SafeTensorsFile file;
  for (const auto& [name, shape] : Vgg19FeaturesImpl::ExpectedTensors()) {
    const int64_t fan_in = shape.size() == 4 ? shape[1] * 9 : 1;
    const torch::Tensor t = (torch::randn(shape) * std::sqrt(2.0 / fan_in)).contiguous();
    file.Add(SafeTensor::FromFloats(name, shape, t.data_ptr<float>()));
  }
  const std::string path = dir_->path() + "/vgg19.safetensors";
  WriteSafeTensors(path, file);
  LossOptions vgg;
  vgg.kind = "l1+vgg19";
  vgg.vgg19_path = path;
  TrainingLoss loss(vgg, torch::kCPU);
  EXPECT_EQ(loss.Name(), "l1+vgg19");
  const torch::Tensor a = torch::rand({1, 3, 32, 32});
  const torch::Tensor b = torch::rand({1, 3, 32, 32}).requires_grad_(true);
  EXPECT_NEAR(loss(a, a).second, 0.0, 1e-7);
  LossValue d = loss(b, a);
  EXPECT_GT(d.second, 0.0);
  d.total.backward();
  EXPECT_GT(b.grad().abs().sum().item<float>(), 0.f);
  // A file missing a layer names it.
  SafeTensorsFile partial;
  for (const auto& t : file.tensors) {
    if (t.name != "features.21.weight") partial.Add(t);
  }
  WriteSafeTensors(dir_->path() + "/vgg_partial.safetensors", partial);
  try {
    vgg.vgg19_path = dir_->path() + "/vgg_partial.safetensors";
    TrainingLoss bad(vgg, torch::kCPU);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("features.21.weight"), std::string::npos)
        << e.what();
  }
}

TEST_F(TrainerTest, LpipsWeightsMakeTheLossAndTheValidationColumns) {
  const std::string weights =
      testing::WriteRandomLpips(dir_->path() + "/lpips_alex.safetensors", "alex");
  TrainOptions o = Options("lpips");
  o.max_steps = 2;
  o.val_scene_list = dir_->path() + "/val.txt";
  o.val_views = 2;
  // A file of an older run: its header gains the new columns, its row stays.
  std::filesystem::create_directories(o.output_path);
  testing::WriteTextFile(o.output_path + "/validation.csv",
                         "step,scene,views,psnr,ssim,seconds_per_view,ulr_psnr,ulr_ssim\n"
                         "0,all,2,20,0.8,0.1,20,0.8\n");
  {
    // From the environment, as a shell would set it (the flag is tested by eval).
    testing::ScopedEnv env(kLpipsPathEnv, weights.c_str());
    const ValidationResult v = Trainer(o).Validate();
    EXPECT_TRUE(v.has_lpips);
    EXPECT_GT(v.lpips, 0.0);
    EXPECT_GT(v.ulr_lpips, 0.0);
    RunTraining(o);
  }
  const std::string csv = ReadFileToString(o.output_path + "/validation.csv");
  EXPECT_EQ(
      csv.rfind("step,scene,views,psnr,ssim,seconds_per_view,ulr_psnr,ulr_ssim,lpips,"
                "ulr_lpips\n0,all,2,20,0.8,0.1,20,0.8\n",
                0),
      0u)
      << csv;
  EXPECT_NE(csv.find("\n2,all,2,"), std::string::npos) << csv;
  EXPECT_EQ(csv.find("n/a"), std::string::npos) << csv;
  const std::string card = ReadFileToString(o.output_path + "/model.json");
  EXPECT_NE(card.find("\"loss\": \"l1+lpips\""), std::string::npos) << card;
  EXPECT_NE(card.find("\"lpips_weight\": 1.0"), std::string::npos) << card;
  EXPECT_NE(card.find("\"ulr_lpips\""), std::string::npos) << card;

  // Explicit choices: SSIM with the weights at hand; LPIPS without them is an error.
  TrainOptions ssim = Options("lpips_ssim");
  ssim.max_steps = 1;
  ssim.lpips_path = weights;
  ssim.loss = "l1+ssim";
  RunTraining(ssim);
  EXPECT_NE(
      ReadFileToString(ssim.output_path + "/model.json").find("\"loss\": \"l1+ssim\""),
      std::string::npos);
  TrainOptions missing = Options("lpips_missing");
  missing.lpips_path = dir_->path() + "/no_such_lpips.safetensors";
  missing.loss = "l1+lpips";
  testing::ExpectError([&] { Trainer trainer(missing); },
                       {"no_such_lpips.safetensors", "no such file"});
  missing.loss = "auto";  // the default goes on without LPIPS
  EXPECT_EQ(Trainer(missing).Validate().has_lpips, false);
}

TEST_F(TrainerTest, StandaloneBinaryReportsBadListsWithTheLine) {
  const std::string binary = std::string(FVS_BINARY_DIR) + "/bin/fvs_train_main";
  ASSERT_TRUE(std::filesystem::exists(binary)) << "build the fvs_train_main target";
  testing::WriteTextFile(dir_->path() + "/missing.txt", "scene_a\n\nnowhere\n");
  std::string output;
  const int rc =
      testing::RunShell(binary + " --scene_list " + dir_->path() +
                            "/missing.txt --output_path " + dir_->path() + "/cli 2>&1",
                        &output);
  EXPECT_NE(rc, 0);
  EXPECT_NE(output.find("missing.txt:3"), std::string::npos) << output;
  EXPECT_EQ(testing::RunShell(binary + " -h > /dev/null"), 0);
}

}  // namespace
}  // namespace fvs
