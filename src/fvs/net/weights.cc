// FvsNet <-> safetensors. Names are the module paths of LibTorch (named_parameters and
// named_buffers), so a file is self-describing and a Python script can read it with
// safetensors.torch.load_file.
#include <cstring>

#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"

namespace fvs {
namespace {

const char kConfigKey[] = "fvs_config";
// Long lists are cut after this many names (the count of the rest is given).
constexpr size_t kMaxListed = 8;

std::vector<std::pair<std::string, torch::Tensor>> NamedTensors(const FvsNetImpl& net) {
  std::vector<std::pair<std::string, torch::Tensor>> out;
  for (const auto& p : net.named_parameters()) out.emplace_back(p.key(), p.value());
  for (const auto& b : net.named_buffers()) out.emplace_back(b.key(), b.value());
  return out;
}

std::string ListProblems(const std::string& title,
                         const std::vector<std::string>& items) {
  std::string s = title + " (" + std::to_string(items.size()) + "): ";
  for (size_t i = 0; i < items.size() && i < kMaxListed; ++i)
    s += (i ? ", " : "") + items[i];
  if (items.size() > kMaxListed) {
    s += ", ... and " + std::to_string(items.size() - kMaxListed) + " more";
  }
  return s;
}

}  // namespace

void SaveWeights(const FvsNet& net, const ModelConfig& config, const std::string& path,
                 bool fp16) {
  SafeTensorsFile file;
  file.metadata[kConfigKey] = config.ToJson();
  file.metadata["format"] = "pt";  // what safetensors.torch writes: tools recognise it
  file.metadata["fvs_weights_version"] = "1";
  for (const auto& [name, value] : NamedTensors(*net)) {
    torch::Tensor t = value.detach().to(torch::kCPU).to(torch::kFloat).contiguous();
    Require(torch::isfinite(t).all().item<bool>(), path,
            "cannot save: tensor '" + name + "' holds NaN or Inf");
    SafeTensor out;
    out.name = name;
    out.shape = t.sizes().vec();
    if (fp16) {
      t = t.to(torch::kHalf).contiguous();
      Require(torch::isfinite(t).all().item<bool>(), path,
              "cannot save as fp16: tensor '" + name + "' exceeds the fp16 range");
      out.dtype = SafeDtype::kF16;
    } else {
      out.dtype = SafeDtype::kF32;
    }
    const size_t bytes = static_cast<size_t>(t.numel()) * t.element_size();
    out.data.resize(bytes);
    if (bytes) std::memcpy(out.data.data(), t.data_ptr(), bytes);
    file.Add(std::move(out));
  }
  WriteSafeTensors(path, file);
}

void LoadWeightsInto(FvsNet& net, const SafeTensorsFile& file,
                     const std::string& subject) {
  std::vector<std::string> missing, unexpected, wrong_shape, wrong_dtype;
  const auto expected = NamedTensors(*net);
  for (const auto& [name, value] : expected) {
    const SafeTensor* t = file.Find(name);
    if (!t) {
      missing.push_back(name);
      continue;
    }
    if (t->shape != value.sizes().vec()) {
      wrong_shape.push_back(name + " " + ShapeString(t->shape) + " instead of " +
                            ShapeString(value.sizes().vec()));
    }
    if (t->dtype != SafeDtype::kF32 && t->dtype != SafeDtype::kF16 &&
        t->dtype != SafeDtype::kBF16) {
      wrong_dtype.push_back(name + " " + SafeDtypeName(t->dtype));
    }
  }
  for (const SafeTensor& t : file.tensors) {
    bool known = false;
    for (const auto& e : expected) known = known || e.first == t.name;
    if (!known) unexpected.push_back(t.name);
  }
  std::vector<std::string> problems;
  if (!missing.empty()) problems.push_back(ListProblems("missing", missing));
  if (!unexpected.empty()) problems.push_back(ListProblems("unexpected", unexpected));
  if (!wrong_shape.empty()) problems.push_back(ListProblems("wrong shape", wrong_shape));
  if (!wrong_dtype.empty()) {
    problems.push_back(
        ListProblems("wrong dtype (F32, F16 or BF16 expected)", wrong_dtype));
  }
  if (!problems.empty()) {
    std::string message =
        "weights do not match network variant '" + net->config().variant + "': ";
    for (size_t i = 0; i < problems.size(); ++i) message += (i ? "; " : "") + problems[i];
    throw Error(subject, message);
  }

  torch::NoGradGuard no_grad;
  for (auto& [name, value] : expected) {
    const SafeTensor& t = *file.Find(name);
    const torch::ScalarType type = t.dtype == SafeDtype::kF32   ? torch::kFloat
                                   : t.dtype == SafeDtype::kF16 ? torch::kHalf
                                                                : torch::kBFloat16;
    // from_blob does not copy: the bytes live in `file` while we copy them into the net.
    const torch::Tensor source =
        torch::from_blob(const_cast<uint8_t*>(t.data.data()), t.shape, torch::dtype(type))
            .to(torch::kFloat);
    Require(torch::isfinite(source).all().item<bool>(), subject,
            "tensor '" + name + "' holds NaN or Inf");
    value.copy_(source.to(value.device()));
  }
}

FvsNet LoadModel(const std::string& path, ModelConfig* config) {
  const SafeTensorsFile file = ReadSafeTensors(path);
  const auto it = file.metadata.find(kConfigKey);
  Require(it != file.metadata.end(), path,
          std::string("no network config (__metadata__[\"") + kConfigKey +
              "\"]): not a colmap-fvs weights file");
  ModelConfig loaded;
  try {
    loaded = ModelConfig::FromJson(it->second);
  } catch (const Error& e) {
    throw Error(path, e.what());
  }
  FvsNet net(loaded);
  LoadWeightsInto(net, file, path);
  if (config) *config = loaded;
  return net;
}

}  // namespace fvs
