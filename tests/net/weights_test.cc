// The safetensors container (against bytes built here from the format's spec) and the
// network's weights: save/load round trips in fp32 and fp16, and every kind of mismatch.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fvs/net/net.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::TempDir;

std::string LittleEndian64(uint64_t n) {
  std::string s(8, '\0');
  for (int i = 0; i < 8; ++i) s[i] = static_cast<char>((n >> (8 * i)) & 0xff);
  return s;
}

template <typename T>
std::string Bytes(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()),
                     values.size() * sizeof(T));
}

std::string MakeFile(const std::string& header, const std::string& data) {
  return LittleEndian64(header.size()) + header + data;
}

// Expects ParseSafeTensors to throw an fvs::Error naming the subject and containing
// `what`.
void ExpectParseError(const std::string& bytes, const std::string& what) {
  try {
    ParseSafeTensors(bytes, "probe.safetensors");
    ADD_FAILURE() << "accepted; expected an error about '" << what << "'";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("probe.safetensors: ", 0), 0u) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

TEST(SafeTensorsTest, ReadsAFileBuiltFromTheSpec) {
  // Two tensors (F32 [2] and F16 [1,2]), metadata, header padded with spaces.
  const std::string header =
      R"({"__metadata__":{"k":"v"},"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
      R"("b":{"dtype":"F16","shape":[1,2],"data_offsets":[8,12]}}   )";
  const std::string data = Bytes(std::vector<float>{1.5f, -2.0f}) +
                           Bytes(std::vector<uint16_t>{0x3C00, 0xC000});
  const SafeTensorsFile file = ParseSafeTensors(MakeFile(header, data), "spec");
  ASSERT_EQ(file.tensors.size(), 2u);
  EXPECT_EQ(file.metadata.at("k"), "v");
  const SafeTensor* a = file.Find("a");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->dtype, SafeDtype::kF32);
  EXPECT_EQ(a->shape, std::vector<int64_t>({2}));
  EXPECT_EQ(a->ToFloats(), std::vector<float>({1.5f, -2.0f}));
  const SafeTensor* b = file.Find("b");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->dtype, SafeDtype::kF16);
  EXPECT_EQ(b->ToFloats(), std::vector<float>({1.0f, -2.0f}));
}

TEST(SafeTensorsTest, WritesTheSpecLayout) {
  SafeTensorsFile file;
  file.metadata["fvs_config"] = "{\"variant\":\"fvs\"}";
  const std::vector<float> values = {0.25f, 1.0f, -3.0f, 7.0f, 8.0f, 9.0f};
  file.Add(SafeTensor::FromFloats("z.weight", {2, 3}, values.data()));
  SafeTensor bytes;
  bytes.name = "a.flags";
  bytes.dtype = SafeDtype::kU8;
  bytes.shape = {3};
  bytes.data = {1, 2, 3};
  file.Add(bytes);

  const std::string out = SerializeSafeTensors(file);
  uint64_t n = 0;
  std::memcpy(&n, out.data(), 8);
  ASSERT_LE(8 + n, out.size());
  EXPECT_EQ(n % 8, 0u);  // tensor data 8-byte aligned
  const std::string header = out.substr(8, n);
  const auto json = nlohmann::json::parse(header);
  EXPECT_EQ(json["__metadata__"]["fvs_config"], "{\"variant\":\"fvs\"}");
  // Sorted by name: a.flags first, then z.weight.
  EXPECT_EQ(json["a.flags"]["dtype"], "U8");
  EXPECT_EQ(json["a.flags"]["data_offsets"], nlohmann::json({0, 3}));
  EXPECT_EQ(json["z.weight"]["dtype"], "F32");
  EXPECT_EQ(json["z.weight"]["shape"], nlohmann::json({2, 3}));
  EXPECT_EQ(json["z.weight"]["data_offsets"], nlohmann::json({3, 27}));
  EXPECT_EQ(out.size(), 8 + n + 27);
  EXPECT_EQ(out.substr(8 + n, 3), std::string("\x01\x02\x03"));
  EXPECT_EQ(out.substr(8 + n + 3), Bytes(values));

  // Round trip through a file.
  TempDir dir;
  WriteSafeTensors(dir / "t.safetensors", file);
  const SafeTensorsFile back = ReadSafeTensors(dir / "t.safetensors");
  EXPECT_EQ(back.Find("z.weight")->ToFloats(), values);
  EXPECT_EQ(back.Find("a.flags")->data, bytes.data);
  EXPECT_EQ(back.metadata, file.metadata);
}

TEST(SafeTensorsTest, RejectsBrokenFiles) {
  const std::string good_header =
      R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]}})";
  const std::string data = Bytes(std::vector<float>{1, 2});
  ASSERT_NO_THROW(ParseSafeTensors(MakeFile(good_header, data), "probe.safetensors"));

  ExpectParseError("abc", "shorter than the 8-byte header length");
  ExpectParseError(LittleEndian64(1000) + "{}", "does not fit in the file");
  const std::string whole = MakeFile(good_header, data);
  ExpectParseError(whole.substr(0, whole.size() - 1), "truncated");
  ExpectParseError(MakeFile("[1,2]", ""), "does not start with '{'");
  ExpectParseError(MakeFile("{\"a\": ", ""), "not valid JSON");
  ExpectParseError(
      MakeFile(R"({"a":{"dtype":"F8","shape":[2],"data_offsets":[0,2]}})", "xx"),
      "unknown dtype");
  ExpectParseError(
      MakeFile(R"({"a":{"dtype":"F32","shape":[3],"data_offsets":[0,8]}})", data),
      "needs 12 bytes");
  ExpectParseError(
      MakeFile(R"({"a":{"dtype":"F32","shape":[-2],"data_offsets":[0,8]}})", data),
      "non-negative integer");
  ExpectParseError(MakeFile(R"({"a":{"dtype":"F32","shape":[2]}})", data),
                   "data_offsets");
  ExpectParseError(MakeFile(R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
                            R"("b":{"dtype":"F32","shape":[1],"data_offsets":[4,8]}})",
                            data),
                   "overlaps");
  ExpectParseError(
      MakeFile(R"({"a":{"dtype":"F32","shape":[1],"data_offsets":[4,8]}})", data),
      "unused bytes");
  ExpectParseError(MakeFile(good_header, data + "junk"), "not described by the header");
  ExpectParseError(MakeFile(R"({"__metadata__":{"k":3}})", ""), "is not a string");
  ExpectParseError(
      MakeFile(R"({"a":{"dtype":"F32","shape":[4294967296,4294967296,4294967296],)"
               R"("data_offsets":[0,8]}})",
               data),
      "impossible shape");

  TempDir dir;
  try {
    ReadSafeTensors(dir / "missing.safetensors");
    ADD_FAILURE() << "missing file accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.safetensors"), std::string::npos);
  }
}

TEST(SafeTensorsTest, HalfAndBFloat16Conversions) {
  EXPECT_EQ(FloatToHalf(1.0f), 0x3C00);
  EXPECT_EQ(FloatToHalf(-2.0f), 0xC000);
  EXPECT_EQ(FloatToHalf(65504.0f), 0x7BFF);
  EXPECT_EQ(FloatToHalf(65520.0f), 0x7C00);  // rounds to inf
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -26)), 0x0000);
  EXPECT_EQ(FloatToHalf(0.1f), 0x2E66);
  EXPECT_EQ(FloatToBFloat16(1.0f), 0x3F80);
  EXPECT_EQ(BFloat16ToFloat(0x3F80), 1.0f);
  // Every non-NaN half survives half -> float -> half.
  for (uint32_t bits = 0; bits < 0x10000; ++bits) {
    const float f = HalfToFloat(static_cast<uint16_t>(bits));
    if (std::isnan(f)) continue;
    ASSERT_EQ(FloatToHalf(f), bits) << bits;
  }
  // Float -> half agrees with LibTorch's conversion (round to nearest even).
  torch::manual_seed(0);
  const torch::Tensor x = torch::randn({20000}) * torch::exp(torch::randn({20000}) * 6);
  const torch::Tensor h = x.to(torch::kHalf).contiguous();
  const float* xp = x.data_ptr<float>();
  const uint16_t* hp = reinterpret_cast<const uint16_t*>(h.data_ptr());
  for (int64_t i = 0; i < x.numel(); ++i) ASSERT_EQ(FloatToHalf(xp[i]), hp[i]) << xp[i];
}

// A small network of the reference layout (and 7 GRUs), so that files stay small.
ModelConfig SmallConfig() {
  return ModelConfig::FromJson(
      R"({"variant":"fvs","feature_channels":8,"encoder_channels":[8,12,16],)"
      R"("blend_channels":[8,12,16,24]})");
}

torch::Tensor Render(FvsNet& net) {
  torch::manual_seed(11);
  net->eval();
  torch::NoGradGuard no_grad;
  const torch::Tensor images = torch::rand({2, 3, 19, 23}) * 2 - 1;
  const torch::Tensor grid = torch::rand({2, 17, 21, 2}) * 2 - 1;
  return net
      ->Forward(images, grid, torch::ones({1, 1, 17, 21}), torch::ones({2, 1, 17, 21}))
      .rgb;
}

TEST(WeightsTest, RoundTripFp32AndFp16) {
  TempDir dir;
  torch::manual_seed(9);
  FvsNet net(SmallConfig());
  const torch::Tensor reference = Render(net);
  for (const bool fp16 : {false, true}) {
    SCOPED_TRACE(fp16 ? "fp16" : "fp32");
    const std::string path = dir / (fp16 ? "w16.safetensors" : "w32.safetensors");
    SaveWeights(net, SmallConfig(), path, fp16);
    const SafeTensorsFile file = ReadSafeTensors(path);
    EXPECT_EQ(file.tensors.size(), net->named_parameters().size());
    for (const SafeTensor& t : file.tensors) {
      EXPECT_EQ(t.dtype, fp16 ? SafeDtype::kF16 : SafeDtype::kF32) << t.name;
    }
    ModelConfig config;
    FvsNet loaded = LoadModel(path, &config);
    EXPECT_EQ(config.ToJson(), SmallConfig().ToJson());
    for (const auto& p : net->named_parameters()) {
      const torch::Tensor expected =
          fp16 ? p.value().detach().to(torch::kHalf).to(torch::kFloat)
               : p.value().detach();
      EXPECT_TRUE(torch::equal(loaded->named_parameters()[p.key()], expected)) << p.key();
    }
    const torch::Tensor again = Render(loaded);
    if (fp16) {
      EXPECT_LT((again - reference).abs().max().item<float>(), 1e-2f);
    } else {
      EXPECT_TRUE(torch::equal(again, reference));
    }
  }

  // BF16 files (as some trainers write) load too, rounded to bf16.
  SafeTensorsFile file = ReadSafeTensors(dir / "w32.safetensors");
  for (SafeTensor& t : file.tensors) {
    const std::vector<float> values = t.ToFloats();
    t.dtype = SafeDtype::kBF16;
    t.data.resize(values.size() * 2);
    for (size_t i = 0; i < values.size(); ++i) {
      const uint16_t b = FloatToBFloat16(values[i]);
      std::memcpy(t.data.data() + 2 * i, &b, 2);
    }
  }
  WriteSafeTensors(dir / "bf16.safetensors", file);
  FvsNet bf16 = LoadModel(dir / "bf16.safetensors", nullptr);
  for (const auto& p : net->named_parameters()) {
    EXPECT_TRUE(torch::equal(bf16->named_parameters()[p.key()],
                             p.value().detach().to(torch::kBFloat16).to(torch::kFloat)))
        << p.key();
  }
}

// Every variant left in src/fvs/net (doc/network.md) builds, renders and comes back from
// its weights file (fp16, as shipped) rendering what it rendered. Its widths are cut
// where it has an encoder, so that the paper's network stays small here.
TEST(WeightsTest, EveryVariantRoundTripsThroughItsWeightsFile) {
  TempDir dir;
  torch::manual_seed(12);
  const torch::Tensor images = torch::rand({3, 3, 19, 23}) * 2 - 1;
  const torch::Tensor grid = torch::rand({3, 17, 21, 2}) * 2.2 - 1.1;
  const torch::Tensor valid_depth = torch::ones({1, 1, 17, 21});
  const torch::Tensor valid_warp = (torch::rand({3, 1, 17, 21}) > 0.3).to(torch::kFloat);
  const torch::Tensor ulr = torch::log(torch::rand({3, 1, 17, 21}).clamp_min(1e-4));
  for (const std::string& name : ModelConfig::KnownVariants()) {
    SCOPED_TRACE(name);
    ModelConfig config = ModelConfig::ForVariant(name);
    if (config.feature_channels > 0) {
      config.feature_channels = 8;
      config.encoder_channels = {8, 12, 16};
      config.blend_channels = {8, 12, 16, 24};
    }
    torch::manual_seed(13);
    FvsNet net(config);
    {  // random heads too, so that the weights decide the image
      torch::NoGradGuard no_grad;
      for (auto& p : net->parameters()) p.normal_(0, 0.1);
    }
    auto render = [&](FvsNet& n) {
      n->eval();
      torch::NoGradGuard no_grad;
      return n->Forward(images, grid, valid_depth, valid_warp, ulr).rgb;
    };
    const torch::Tensor reference = render(net);
    ASSERT_TRUE(torch::isfinite(reference).all().item<bool>());
    const std::string path = dir / (name + ".safetensors");
    SaveWeights(net, config, path, /*fp16=*/true);
    ModelConfig read;
    FvsNet loaded = LoadModel(path, &read);
    EXPECT_EQ(read.ToJson(), config.ToJson());
    EXPECT_LT((render(loaded) - reference).abs().max().item<float>(), 2e-2f);
  }
}

// The files must be readable by Python's safetensors; that package cannot be installed
// here, so a standard-library reader that applies the reference implementation's checks
// (tests/net/read_safetensors.py) reads them and sums every tensor.
TEST(WeightsTest, ReadableByAnIndependentReader) {
  if (testing::RunShell("python3 -c pass") != 0) GTEST_SKIP() << "python3 not found";
  const std::string script =
      std::string(FVS_SOURCE_DIR) + "/tests/net/read_safetensors.py";
  TempDir dir;
  torch::manual_seed(10);
  FvsNet net(SmallConfig());
  for (const bool fp16 : {false, true}) {
    SCOPED_TRACE(fp16 ? "fp16" : "fp32");
    const std::string path = dir / "w.safetensors";
    SaveWeights(net, SmallConfig(), path, fp16);
    std::string output;
    ASSERT_EQ(testing::RunShell("python3 " + script + " " + path + " 2>&1", &output), 0)
        << output;
    std::map<std::string, std::pair<std::string, double>> read;  // name -> (dtype, sum)
    std::istringstream lines(output);
    std::string name, dtype, shape;
    double sum = 0;
    while (lines >> name >> dtype) {
      if (name == "metadata") {
        std::getline(lines, shape);
        continue;
      }
      lines >> shape >> sum;
      read[name] = {dtype, sum};
    }
    ASSERT_EQ(read.size(), net->named_parameters().size()) << output;
    for (const auto& p : net->named_parameters()) {
      ASSERT_EQ(read.count(p.key()), 1u) << p.key();
      EXPECT_EQ(read[p.key()].first, fp16 ? "F16" : "F32");
      const torch::Tensor v = fp16 ? p.value().to(torch::kHalf).to(torch::kDouble)
                                   : p.value().to(torch::kDouble);
      EXPECT_NEAR(read[p.key()].second, v.sum().item<double>(), 1e-4) << p.key();
    }
    EXPECT_NE(output.find("metadata fvs_config={\"variant\":\"fvs\""), std::string::npos);
  }
  // The reader is not a rubber stamp: a truncated file fails.
  const std::string bytes = ReadFileToString(dir / "w.safetensors");
  WriteFileAtomic(dir / "cut.safetensors",
                  [&](std::ostream& out) { out << bytes.substr(0, bytes.size() - 2); });
  EXPECT_NE(testing::RunShell("python3 " + script + " " + (dir / "cut.safetensors") +
                              " 2>/dev/null"),
            0);
}

// Expects LoadModel to throw an fvs::Error naming the file and containing every `what`.
void ExpectLoadError(const std::string& path, const std::vector<std::string>& whats) {
  try {
    LoadModel(path, nullptr);
    ADD_FAILURE() << "loaded; expected an error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& what : whats) {
      EXPECT_NE(message.find(what), std::string::npos)
          << "'" << what << "' not in: " << message;
    }
  }
}

TEST(WeightsTest, MismatchesAreNamed) {
  TempDir dir;
  FvsNet net(SmallConfig());
  const std::string good = dir / "good.safetensors";
  SaveWeights(net, SmallConfig(), good, false);
  const SafeTensorsFile original = ReadSafeTensors(good);
  const std::string bad = dir / "bad.safetensors";

  {  // missing + unexpected (a renamed tensor)
    SafeTensorsFile f = original;
    for (SafeTensor& t : f.tensors) {
      if (t.name == "rgb_head.weight") t.name = "rgb_head.kernel";
    }
    WriteSafeTensors(bad, f);
    ExpectLoadError(bad, {"variant 'fvs'", "missing (1): rgb_head.weight",
                          "unexpected (1): rgb_head.kernel"});
  }
  {  // wrong shape
    SafeTensorsFile f = original;
    for (SafeTensor& t : f.tensors) {
      if (t.name == "confidence_head.bias") {
        t.shape = {2};
        t.data.resize(8);
      }
    }
    WriteSafeTensors(bad, f);
    ExpectLoadError(bad, {"wrong shape (1): confidence_head.bias [2] instead of [1]"});
  }
  {  // wrong dtype
    SafeTensorsFile f = original;
    for (SafeTensor& t : f.tensors) {
      if (t.name == "confidence_head.bias") t.dtype = SafeDtype::kI32;
    }
    WriteSafeTensors(bad, f);
    ExpectLoadError(bad, {"wrong dtype", "confidence_head.bias I32"});
  }
  {  // NaN in a weight
    SafeTensorsFile f = original;
    for (SafeTensor& t : f.tensors) {
      if (t.name == "confidence_head.bias") {
        const float nan = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(t.data.data(), &nan, 4);
      }
    }
    WriteSafeTensors(bad, f);
    ExpectLoadError(bad, {"confidence_head.bias", "NaN or Inf"});
  }
  {  // weights of another variant (fvs_nogru has no GRUs, plain convs instead)
    SafeTensorsFile f = original;
    f.metadata["fvs_config"] =
        R"({"variant":"fvs_nogru","feature_channels":8,)"
        R"("encoder_channels":[8,12,16],"blend_channels":[8,12,16,24]})";
    WriteSafeTensors(bad, f);
    ExpectLoadError(
        bad, {"variant 'fvs_nogru'", "missing (14)", "unexpected (28)", "... and"});
  }
  {  // no config, unknown variant
    SafeTensorsFile f = original;
    f.metadata.clear();
    WriteSafeTensors(bad, f);
    ExpectLoadError(bad, {"no network config"});
    f.metadata["fvs_config"] = R"({"variant":"fvs_huge"})";
    WriteSafeTensors(bad, f);
    ExpectLoadError(bad, {"fvs_huge", "known: fvs,"});
  }
  {  // truncated file, bad header
    const std::string bytes = ReadFileToString(good);
    WriteFileAtomic(bad,
                    [&](std::ostream& out) { out << bytes.substr(0, bytes.size() - 5); });
    ExpectLoadError(bad, {"truncated"});
    std::string broken = bytes;
    broken[8] = '[';
    WriteFileAtomic(bad, [&](std::ostream& out) { out << broken; });
    ExpectLoadError(bad, {"header"});
  }
}

}  // namespace
}  // namespace fvs
