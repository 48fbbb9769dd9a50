// The FVS network: layouts of every variant, parameter and FLOP counts against the
// reference layout computed by hand, the softmax blend at extreme confidences, warping,
// recurrence and determinism. Random weights made here; small inputs (2 threads,
// seconds).
#include "fvs/net/net.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fvs/util/error.h"

namespace fvs {
namespace {

// The reference layout (4 levels, 7 GRUs) of a variant at small widths: fast to run.
ModelConfig Small(const std::string& variant) {
  ModelConfig c = ModelConfig::ForVariant(variant);
  c.feature_channels = 8;
  c.encoder_channels = {8, 12, 16};
  c.blend_channels = {8, 12, 16, 24};
  return c;
}

// Parameters of a dense kxk conv with bias.
int64_t ConvParams(int64_t in, int64_t out, int64_t k = 3) {
  return in * out * k * k + out;
}
// A ConvGRU with hidden = in = c: gates conv(2c -> 2c), candidate conv(2c -> c).
int64_t GruParams(int64_t in, int64_t c) {
  return ConvParams(in + c, 2 * c) + ConvParams(in + c, c);
}

struct Inputs {
  torch::Tensor images, grid, valid_depth, valid_warp;
  torch::Tensor ulr;  // ULR log-weights, the prior of fvs_fast
};

// K sources of an odd size, a target of another odd size; about 70% of the warp valid.
Inputs MakeInputs(int k, int target_h, int target_w, int source_h = 37,
                  int source_w = 53) {
  torch::manual_seed(7);
  Inputs in;
  in.images = torch::rand({k, 3, source_h, source_w}) * 2 - 1;
  in.grid = torch::rand({k, target_h, target_w, 2}) * 2.2 - 1.1;
  in.valid_depth = (torch::rand({1, 1, target_h, target_w}) > 0.2).to(torch::kFloat);
  in.valid_warp = (torch::rand({k, 1, target_h, target_w}) > 0.3).to(torch::kFloat);
  in.ulr = torch::log(torch::rand({k, 1, target_h, target_w}).clamp_min(1e-4));
  return in;
}

// One training forward and backward on random inputs; every parameter must get a finite
// gradient.
void ExpectFiniteGradients(FvsNet& net, const Inputs& in) {
  net->train();
  net->zero_grad();
  const BlendOutput out =
      net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp, in.ulr);
  (out.rgb - 0.5).abs().mean().backward();
  for (const auto& p : net->named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
    EXPECT_TRUE(torch::isfinite(p.value().grad()).all().item<bool>()) << p.key();
  }
}

TEST(ModelConfigTest, VariantsAndJson) {
  for (const std::string& name : ModelConfig::KnownVariants()) {
    const ModelConfig c = ModelConfig::ForVariant(name);
    const ModelConfig back = ModelConfig::FromJson(c.ToJson());
    EXPECT_EQ(back.ToJson(), c.ToJson()) << name;
  }
  EXPECT_FALSE(ModelConfig::ForVariant("fvs_nogru").use_gru);
  EXPECT_FALSE(ModelConfig::ForVariant("fvs_nomasks").use_masks);
  EXPECT_FALSE(ModelConfig::ForVariant("fvs_noinfdepth").inf_depth);
  EXPECT_FALSE(ModelConfig::ForVariant("fvs_single").soft_argmax);
  EXPECT_EQ(ModelConfig::ForVariant("fvs_nomasks").BlendInputChannels(), 64);
  EXPECT_EQ(ModelConfig::ForVariant("fvs").BlendInputChannels(), 66);
  try {
    ModelConfig::ForVariant("fvs_huge");
    FAIL() << "unknown variant accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fvs_huge"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("fvs_fast"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ModelConfig::FromJson("{\"variant\": 3}"), Error);
  EXPECT_THROW(ModelConfig::FromJson("not json"), Error);
  EXPECT_THROW(
      ModelConfig::FromJson("{\"variant\": \"fvs\", \"feature_channels\": \"x\"}"),
      Error);
  EXPECT_THROW(ModelConfig::FromJson("{\"variant\": \"fvs\", \"blend_channels\": [8]}"),
               Error);
  EXPECT_THROW(ModelConfig::FromJson("{\"variant\": \"fvs\", \"use_gr\": false}"), Error);
  // Numbers that are no int (get<int>() of them was undefined behaviour; the
  // safetensors fuzzer found -1e30 in a weights file's fvs_config).
  for (const char* bad : {"[17, 24, -1e30]", "[17, 24.5]", "[4294967297, 24]"}) {
    EXPECT_THROW(ModelConfig::FromJson(std::string("{\"variant\": \"fvs_agg\", "
                                                   "\"blend_channels\": ") +
                                       bad + "}"),
                 Error)
        << bad;
  }
  EXPECT_THROW(ModelConfig::FromJson("{\"variant\": \"fvs\", \"ulr_num_blend\": 1e30}"),
               Error);
  EXPECT_EQ(
      ModelConfig::FromJson("{\"variant\": \"fvs_agg\", \"blend_channels\": [16.0, 24]}")
          .blend_channels,
      (std::vector<int>{16, 24}));
  EXPECT_THROW(ModelConfig::FromJson("{\"variant\": \"fvs\", \"feature_channels\": -1}"),
               Error);
  const ModelConfig custom =
      ModelConfig::FromJson("{\"variant\": \"fvs\", \"blend_channels\": [8, 16]}");
  EXPECT_EQ(custom.blend_channels, std::vector<int>({8, 16}));
  EXPECT_EQ(custom.feature_channels, 64);
}

TEST(FvsNetTest, ReferenceParameterCountsMatchTheLayout) {
  FvsNet net(ModelConfig::ForVariant("fvs"));
  // VGG16 stages 1-3 and the U-Net decoder (256 up + 128 skip -> 128, 128 up + 64 -> 64).
  const int64_t encoder = ConvParams(3, 64) + ConvParams(64, 64) + ConvParams(64, 128) +
                          ConvParams(128, 128) + ConvParams(128, 256) +
                          2 * ConvParams(256, 256) + ConvParams(384, 128) +
                          ConvParams(128, 128) + ConvParams(192, 64) + ConvParams(64, 64);
  // Blending U-Net 64/128/256/512, decoder 256/128/64; two convs + one ConvGRU per stage.
  const int64_t blender =
      ConvParams(66, 64) + ConvParams(64, 64) + GruParams(64, 64) +              // d0
      ConvParams(64, 128) + ConvParams(128, 128) + GruParams(128, 128) +         // d1
      ConvParams(128, 256) + ConvParams(256, 256) + GruParams(256, 256) +        // d2
      ConvParams(256, 512) + ConvParams(512, 512) + GruParams(512, 512) +        // d3
      ConvParams(512 + 256, 256) + ConvParams(256, 256) + GruParams(256, 256) +  // u2
      ConvParams(256 + 128, 128) + ConvParams(128, 128) + GruParams(128, 128) +  // u1
      ConvParams(128 + 64, 64) + ConvParams(64, 64) + GruParams(64, 64) +        // u0
      ConvParams(64, 3, 1) + ConvParams(64, 1, 1);                               // heads
  EXPECT_EQ(net->EncoderParameterCount(), encoder);
  EXPECT_EQ(net->BlenderParameterCount(), blender);

  int grus = 0;
  for (const auto& m : net->named_modules()) {
    if (m.value()->as<ConvGruImpl>() != nullptr) ++grus;
  }
  EXPECT_EQ(grus, 7);
  int no_gru = 0;
  FvsNet plain(ModelConfig::ForVariant("fvs_nogru"));
  for (const auto& m : plain->named_modules()) {
    if (m.value()->as<ConvGruImpl>() != nullptr) ++no_gru;
  }
  EXPECT_EQ(no_gru, 0);

  // FLOPs at 64x48 (a multiple of 8: no padding): 2 x MACs of every conv at its level.
  const double px = 64.0 * 48.0;
  auto macs = [](int64_t in, int64_t out) { return static_cast<double>(in * out * 9); };
  const double encode =
      2 * px *
      (macs(3, 64) + macs(64, 64) + macs(192, 64) + macs(64, 64) +
       (macs(64, 128) + macs(128, 128) + macs(384, 128) + macs(128, 128)) / 4 +
       (macs(128, 256) + 2 * macs(256, 256)) / 16);
  auto gru = [&](int64_t c) { return macs(2 * c, 2 * c) + macs(2 * c, c); };
  const double blend =
      2 * px *
      (macs(66, 64) + macs(64, 64) + gru(64) + macs(192, 64) + macs(64, 64) + gru(64) +
       (macs(64, 128) + macs(128, 128) + gru(128) + macs(384, 128) + macs(128, 128) +
        gru(128)) /
           4 +
       (macs(128, 256) + macs(256, 256) + gru(256) + macs(768, 256) + macs(256, 256) +
        gru(256)) /
           16 +
       (macs(256, 512) + macs(512, 512) + gru(512)) / 64 + 64 * 4);
  EXPECT_DOUBLE_EQ(net->EncodeFlops(48, 64), encode);
  EXPECT_DOUBLE_EQ(net->BlendFlops(48, 64), blend);

  // The CPU design must be an order of magnitude cheaper per source.
  FvsNet fast(ModelConfig::ForVariant("fvs_fast"));
  const double ratio = (net->EncodeFlops(270, 480) + net->BlendFlops(270, 480)) /
                       (fast->EncodeFlops(270, 480) + fast->BlendFlops(270, 480));
  EXPECT_GT(ratio, 8.0);
}

TEST(FvsNetTest, EveryVariantGivesFiniteImagesOfTheTargetSize) {
  const Inputs in = MakeInputs(3, 40, 56);
  const Inputs odd = MakeInputs(2, 23, 31, 19, 27);
  for (const std::string& name : ModelConfig::KnownVariants()) {
    SCOPED_TRACE(name);
    torch::manual_seed(1);
    FvsNet net(ModelConfig::ForVariant(name));
    net->eval();
    torch::NoGradGuard no_grad;
    const torch::Tensor features = net->Encode(in.images);
    EXPECT_EQ(features.sizes().vec(),
              std::vector<int64_t>({3, net->config().EncodedChannels(), 37, 53}));
    for (const Inputs* x : {&in, &odd}) {
      const int64_t k = x->images.size(0), h = x->grid.size(1), w = x->grid.size(2);
      const BlendOutput out =
          net->Forward(x->images, x->grid, x->valid_depth, x->valid_warp, x->ulr);
      EXPECT_EQ(out.rgb.sizes().vec(), std::vector<int64_t>({1, 3, h, w}));
      EXPECT_TRUE(torch::isfinite(out.rgb).all().item<bool>());
      EXPECT_LE(out.rgb.abs().max().item<float>(), 1.0f);
      if (net->config().soft_argmax) {
        EXPECT_EQ(out.weights.sizes().vec(), std::vector<int64_t>({k, 1, h, w}));
        EXPECT_EQ(out.per_source_rgb.sizes().vec(), std::vector<int64_t>({k, 3, h, w}));
        EXPECT_LT((out.weights.sum(0) - 1).abs().max().item<float>(), 1e-5f);
      } else {
        EXPECT_FALSE(out.weights.defined());
      }
    }
  }
}

TEST(FvsNetTest, BadShapesThrow) {
  FvsNet net(ModelConfig::ForVariant("fvs_fast"));
  torch::NoGradGuard no_grad;
  EXPECT_THROW(net->Encode(torch::zeros({1, 4, 8, 8})), Error);
  EXPECT_THROW(net->Blend(torch::zeros({2, 31, 8, 8}), torch::ones({1, 1, 8, 8}),
                          torch::ones({2, 1, 8, 8})),
               Error);
  EXPECT_THROW(net->Blend(torch::zeros({2, 35, 8, 8}), torch::ones({1, 1, 8, 8}),
                          torch::ones({3, 1, 8, 8})),
               Error);
  EXPECT_THROW(WarpFeatures(torch::zeros({2, 4, 8, 8}), torch::zeros({1, 8, 8, 2})),
               Error);
}

TEST(FvsNetTest, RgbSkipStartsAsThePriorBlendOfTheWarpedSources) {
  // fvs_fast untrained: zero heads, so each source contributes its own warped colour with
  // confidence ulr_prior * (ULR log-weight) + mask_prior * (valid_warp - 1): the ULR
  // blend.
  torch::manual_seed(3);
  FvsNet net(ModelConfig::ForVariant("fvs_fast"));
  ASSERT_TRUE(net->config().rgb_skip);
  const double mask_prior = net->config().mask_prior;
  const double ulr_prior = net->config().ulr_prior;
  ASSERT_GT(ulr_prior, 0);
  net->eval();
  torch::NoGradGuard no_grad;
  const Inputs in = MakeInputs(3, 16, 24);
  const torch::Tensor encoded = net->Encode(in.images);
  EXPECT_TRUE(
      torch::equal(encoded.narrow(1, net->config().feature_channels, 3), in.images));
  // Sources that do not see a pixel offer black there.
  const torch::Tensor warped_rgb = torch::where(
      in.valid_warp > 0.5, WarpFeatures(in.images, in.grid), torch::full({1}, -1.0f));
  const torch::Tensor w =
      torch::exp(mask_prior * (in.valid_warp - 1) + ulr_prior * in.ulr);
  const torch::Tensor expected =
      ((w * warped_rgb).sum(0, true) / w.sum(0, true)).clamp(-1, 1);
  const BlendOutput out =
      net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp, in.ulr);
  EXPECT_LT((out.rgb - expected).abs().max().item<float>(), 1e-5f);
  EXPECT_LT((out.per_source_rgb - warped_rgb).abs().max().item<float>(), 1e-6f);
  // Without its prior the blend refuses to run rather than silently blend uniformly.
  EXPECT_THROW(net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp), Error);
  EXPECT_THROW(net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp,
                            in.ulr.narrow(0, 0, 2)),
               Error);
  // The option is refused where it has no per-source colours to correct.
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_single","rgb_skip":true})"),
               Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_nomasks","mask_prior":2})"),
               Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_fast","mask_prior":-1})"), Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_fast","ulr_prior":-1})"), Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_nomasks","ulr_prior":1})"),
               Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_fast","ulr_num_blend":0})"),
               Error);
}

TEST(FvsAggTest, StartsAsTheUlrBlendAndLearnsEverywhere) {
  // fvs_agg untrained: zero confidence and colour heads and a zero residual, so it
  // renders the ULR blend of the warped photos (black where a source does not see).
  torch::manual_seed(4);
  FvsNet net(ModelConfig::ForVariant("fvs_agg"));
  EXPECT_EQ(net->config().EncodedChannels(), 3);
  EXPECT_EQ(net->EncoderParameterCount(), 0);
  EXPECT_DOUBLE_EQ(net->EncodeFlops(270, 480), 0.0);
  EXPECT_GT(net->BlendFlops(270, 480), 0.0);
  net->eval();
  const Inputs in = MakeInputs(4, 17, 23);
  {
    torch::NoGradGuard no_grad;
    EXPECT_TRUE(torch::equal(net->Encode(in.images), in.images));
    const torch::Tensor warped_rgb = torch::where(
        in.valid_warp > 0.5, WarpFeatures(in.images, in.grid), torch::full({1}, -1.0f));
    const torch::Tensor w = torch::exp(net->config().ulr_prior * in.ulr);
    const torch::Tensor expected =
        ((w * warped_rgb).sum(0, true) / w.sum(0, true)).clamp(-1, 1);
    const BlendOutput out =
        net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp, in.ulr);
    EXPECT_LT((out.rgb - expected).abs().max().item<float>(), 1e-5f);
    // Without its prior it refuses to run.
    EXPECT_THROW(net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp), Error);
  }
  // Every parameter gets a finite gradient, K = 1 included.
  // Odd sizes on purpose: the padded pixels must not reach the gradients.
  for (int k : {1, 3}) ExpectFiniteGradients(net, MakeInputs(k, 16, 21, 20, 28));
  // Bad layouts are refused with a reason.
  EXPECT_THROW(
      ModelConfig::FromJson(R"({"variant":"fvs_agg","encoder_channels":[8,16]})"), Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_agg","ulr_prior":0})"), Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs_agg","blend_channels":[8]})"),
               Error);
  EXPECT_THROW(ModelConfig::FromJson(R"({"variant":"fvs","blender":"mlp"})"), Error);
  // The switch of the removed fvs_agg_rel: false (every fvs_agg file written while it
  // existed) reads as fvs_agg, true is refused with the reason.
  EXPECT_EQ(
      ModelConfig::FromJson(R"({"variant":"fvs_agg","relative_inputs":false})").ToJson(),
      ModelConfig::ForVariant("fvs_agg").ToJson());
  try {
    ModelConfig::FromJson(R"({"variant":"fvs_agg","relative_inputs":true})");
    FAIL() << "relative_inputs true accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fvs_agg_rel"), std::string::npos) << e.what();
  }
}

TEST(FvsAggTest, ExtremeInputsStayFinite) {
  torch::manual_seed(5);
  FvsNet net(ModelConfig::ForVariant("fvs_agg"));
  // Random (not zero) heads, so the extreme inputs reach the blend.
  {
    torch::NoGradGuard no_grad;
    for (auto& p : net->parameters()) p.normal_(0, 0.5);
  }
  net->eval();
  torch::NoGradGuard no_grad;
  const float inf = std::numeric_limits<float>::infinity();
  Inputs in = MakeInputs(3, 12, 14);
  in.ulr.fill_(-1e30f);
  in.ulr[0].fill_(inf);
  in.valid_warp.zero_();  // no source sees anything
  const BlendOutput out =
      net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp, in.ulr);
  EXPECT_TRUE(torch::isfinite(out.rgb).all().item<bool>());
  EXPECT_LE(out.rgb.abs().max().item<float>(), 1.0f);
}

TEST(SoftmaxWeightsTest, FiniteAndNormalisedAtExtremes) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    std::vector<float> confidences;
    std::vector<float> expected;
  };
  const std::vector<Case> cases = {
      {{1e30f, 1e30f, 1e30f}, {1 / 3.f, 1 / 3.f, 1 / 3.f}},
      {{-1e30f, -1e30f, -1e30f, -1e30f}, {0.25f, 0.25f, 0.25f, 0.25f}},
      {{0, 0}, {0.5f, 0.5f}},
      {{1e30f, -1e30f, -1e30f}, {1, 0, 0}},
      {{-1e30f, 3e38f, 0}, {0, 1, 0}},
      {{inf, inf}, {0.5f, 0.5f}},
      {{-inf, 0}, {0, 1}},
      {{nan, 0}, {0, 1}},
      {{nan, nan}, {0.5f, 0.5f}},
      {{std::log(3.0f), 0}, {0.75f, 0.25f}},
      {{42}, {1}},
  };
  for (const Case& c : cases) {
    const int64_t k = static_cast<int64_t>(c.confidences.size());
    // Same confidences at every pixel of a 2x3 image.
    const torch::Tensor conf =
        torch::tensor(c.confidences).view({k, 1, 1, 1}).expand({k, 1, 2, 3}).contiguous();
    const torch::Tensor w = SoftmaxWeights(conf);
    ASSERT_TRUE(torch::isfinite(w).all().item<bool>());
    EXPECT_LT((w.sum(0) - 1).abs().max().item<float>(), 1e-6f);
    for (int64_t i = 0; i < k; ++i) {
      EXPECT_NEAR(w[i].max().item<float>(), c.expected[i], 1e-6f);
      EXPECT_NEAR(w[i].min().item<float>(), c.expected[i], 1e-6f);
    }
  }
}

TEST(SoftmaxWeightsTest, HalfPrecisionConfidences) {
  // fp16 overflows to inf at 65520: equal infinite confidences still share the weight.
  const float inf = std::numeric_limits<float>::infinity();
  const torch::Tensor conf =
      torch::tensor({inf, inf, -inf}).view({3, 1, 1, 1}).to(torch::kHalf);
  const torch::Tensor w = SoftmaxWeights(conf);
  EXPECT_EQ(w.scalar_type(), torch::kHalf);
  const torch::Tensor f = w.to(torch::kFloat).flatten();
  EXPECT_FLOAT_EQ(f[0].item<float>(), 0.5f);
  EXPECT_FLOAT_EQ(f[1].item<float>(), 0.5f);
  EXPECT_FLOAT_EQ(f[2].item<float>(), 0.0f);
}

TEST(FvsNetTest, HugeEqualConfidencesInTheNetworkStayFinite) {
  torch::manual_seed(2);
  FvsNet net(ModelConfig::ForVariant("fvs_fast"));
  net->eval();
  torch::NoGradGuard no_grad;
  for (const double bias : {1e30, -1e30}) {
    for (auto& p : net->named_parameters()) {
      if (p.key() == "confidence_head.weight") p.value().zero_();
      if (p.key() == "confidence_head.bias") p.value().fill_(bias);
    }
    const Inputs in = MakeInputs(3, 16, 24);
    const BlendOutput out =
        net->Forward(in.images, in.grid, in.valid_depth, in.valid_warp, in.ulr);
    EXPECT_TRUE(torch::isfinite(out.rgb).all().item<bool>());
    EXPECT_LT((out.weights - 1.0 / 3).abs().max().item<float>(), 1e-6f);
    // Equal weights: the blend is the mean of the per-source colours (before the clamp).
    EXPECT_LT((out.rgb - out.per_source_rgb.mean(0, true).clamp(-1, 1))
                  .abs()
                  .max()
                  .item<float>(),
              1e-5f);
  }
}

TEST(FvsNetTest, SingleSourceAndDeterminism) {
  torch::manual_seed(3);
  FvsNet net(Small("fvs"));
  net->eval();
  torch::NoGradGuard no_grad;
  const Inputs one = MakeInputs(1, 24, 32);
  const BlendOutput a =
      net->Forward(one.images, one.grid, one.valid_depth, one.valid_warp, one.ulr);
  EXPECT_TRUE(torch::equal(a.weights, torch::ones_like(a.weights)));
  EXPECT_TRUE(torch::allclose(a.rgb, a.per_source_rgb.clamp(-1, 1)));
  const BlendOutput b =
      net->Forward(one.images, one.grid, one.valid_depth, one.valid_warp, one.ulr);
  EXPECT_TRUE(torch::equal(a.rgb, b.rgb));

  const Inputs three = MakeInputs(3, 24, 32);
  const torch::Tensor c = net->Forward(three.images, three.grid, three.valid_depth,
                                       three.valid_warp, three.ulr)
                              .rgb;
  const torch::Tensor d = net->Forward(three.images, three.grid, three.valid_depth,
                                       three.valid_warp, three.ulr)
                              .rgb;
  EXPECT_TRUE(torch::equal(c, d));
}

// The hidden state carries across sources: with the GRU the second source's colour
// depends on the first; without it, it does not.
TEST(FvsNetTest, RecurrenceCarriesAcrossSources) {
  const Inputs in = MakeInputs(2, 16, 24);
  for (const std::string& name : {std::string("fvs"), std::string("fvs_nogru")}) {
    torch::manual_seed(4);
    FvsNet net(Small(name));
    net->eval();
    torch::NoGradGuard no_grad;
    const torch::Tensor warped = WarpFeatures(net->Encode(in.images), in.grid);
    const BlendOutput both = net->Blend(warped, in.valid_depth, in.valid_warp, in.ulr);
    const BlendOutput second =
        net->Blend(warped.narrow(0, 1, 1), in.valid_depth, in.valid_warp.narrow(0, 1, 1));
    const float diff = (both.per_source_rgb.narrow(0, 1, 1) - second.per_source_rgb)
                           .abs()
                           .max()
                           .item<float>();
    if (name == "fvs") {
      EXPECT_GT(diff, 1e-6f);
    } else {
      EXPECT_LT(diff, 1e-5f);
    }
  }
}

TEST(FvsNetTest, NoMasksIgnoresMasks) {
  torch::manual_seed(5);
  FvsNet net(Small("fvs_nomasks"));
  net->eval();
  torch::NoGradGuard no_grad;
  const torch::Tensor warped = torch::rand({2, 8, 16, 16});
  const torch::Tensor a =
      net->Blend(warped, torch::ones({1, 1, 16, 16}), torch::ones({2, 1, 16, 16})).rgb;
  const torch::Tensor b =
      net->Blend(warped, torch::zeros({1, 1, 16, 16}), torch::zeros({2, 1, 16, 16})).rgb;
  EXPECT_TRUE(torch::equal(a, b));
}

TEST(FvsNetTest, TrainingGivesFiniteGradientsEverywhere) {
  // fvs_fast, and a depthwise-separable version of it (the layout the option builds).
  const ModelConfig separable =
      ModelConfig::FromJson(R"({"variant":"fvs_fast","depthwise_separable":true})");
  for (const ModelConfig& config : {ModelConfig::ForVariant("fvs_fast"), separable}) {
    torch::manual_seed(6);
    FvsNet net(config);
    ExpectFiniteGradients(net, MakeInputs(2, 16, 24, 20, 28));
  }
  // Separable units: a depthwise 3x3 without bias and a pointwise 1x1 (far fewer
  // weights).
  FvsNet net(separable);
  EXPECT_EQ(net->named_parameters()["blend_d1_0.dw.weight"].sizes().vec(),
            std::vector<int64_t>({16, 1, 3, 3}));
  EXPECT_EQ(net->named_parameters()["blend_d1_0.pw.weight"].sizes().vec(),
            std::vector<int64_t>({24, 16, 1, 1}));
  EXPECT_LT(net->BlendFlops(64, 64),
            FvsNet(ModelConfig::ForVariant("fvs_fast"))->BlendFlops(64, 64));
}

TEST(WarpFeaturesTest, IdentityGridReproducesAndOutsideIsZero) {
  torch::manual_seed(8);
  const torch::Tensor features = torch::rand({2, 5, 7, 9});
  const torch::Tensor same = WarpFeatures(features, IdentityGrid(2, 7, 9));
  EXPECT_LT((same - features).abs().max().item<float>(), 1e-5f);

  // A half-pixel shift in x averages neighbours.
  torch::Tensor shifted = IdentityGrid(2, 7, 9);
  shifted.select(3, 0).add_(1.0 / 9);
  const torch::Tensor half = WarpFeatures(features, shifted);
  const torch::Tensor expected =
      0.5 * (features.narrow(3, 0, 8) + features.narrow(3, 1, 8));
  EXPECT_LT((half.narrow(3, 0, 8) - expected).abs().max().item<float>(), 1e-5f);
  // The last column now samples the right edge of the image: the border pixel itself,
  // not half of it (no darkened photo edges).
  EXPECT_LT((half.narrow(3, 8, 1) - features.narrow(3, 8, 1)).abs().max().item<float>(),
            1e-5f);

  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const float v : {3.0f, -1.5f, 1e30f, inf, -inf, nan}) {
    const torch::Tensor grid = torch::full({2, 4, 6, 2}, v);
    const torch::Tensor out = WarpFeatures(features, grid);
    EXPECT_EQ(out.sizes().vec(), std::vector<int64_t>({2, 5, 4, 6}));
    EXPECT_TRUE(torch::equal(out, torch::zeros_like(out))) << v;
  }
}

}  // namespace
}  // namespace fvs
