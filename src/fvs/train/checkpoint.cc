// Trainer checkpoints: one torch archive per checkpoint, written atomically, holding
// everything the next step depends on (weights, Adam moments and step counts, the step,
// the sampler's mt19937_64 and LibTorch's CPU generator), so a resumed run continues
// exactly as an uninterrupted one.
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/core/Generator.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "fvs/train/trainer.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

constexpr int64_t kCheckpointFormat = 1;

torch::Tensor StringTensor(const std::string& s) {
  torch::Tensor t = torch::empty({static_cast<int64_t>(s.size())}, torch::kUInt8);
  if (!s.empty()) std::memcpy(t.data_ptr(), s.data(), s.size());
  return t;
}

std::string TensorString(const torch::Tensor& t) {
  const torch::Tensor c = t.to(torch::kCPU).to(torch::kUInt8).contiguous();
  return std::string(reinterpret_cast<const char*>(c.data_ptr()), c.numel());
}

}  // namespace

std::vector<std::pair<int, std::string>> Trainer::ListCheckpoints(
    const std::string& dir) {
  namespace fs = std::filesystem;
  std::vector<std::pair<int, std::string>> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!StartsWith(name, "checkpoint-") || !EndsWith(name, ".pt")) continue;
    const std::string digits = name.substr(11, name.size() - 14);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos ||
        digits.size() > 9) {
      continue;
    }
    out.emplace_back(std::stoi(digits), entry.path().string());
  }
  std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.first > b.first; });
  return out;
}

std::string Trainer::SaveCheckpoint() {
  torch::serialize::OutputArchive archive;
  torch::serialize::OutputArchive model, optimizer;
  net_->save(model);
  optimizer_->save(optimizer);
  archive.write("model", model);
  archive.write("optimizer", optimizer);
  archive.write("format", torch::tensor(kCheckpointFormat, torch::kLong));
  archive.write("step", torch::tensor(static_cast<int64_t>(step_), torch::kLong));
  archive.write("train_seconds", torch::tensor(train_seconds_, torch::kDouble));
  archive.write("config", StringTensor(config_.ToJson()));
  archive.write("sampler_state", StringTensor(sampler_->State()));
  {
    auto generator = at::detail::getDefaultCPUGenerator();
    std::lock_guard<std::mutex> lock(generator.mutex());
    archive.write("torch_cpu_rng", generator.get_state());
  }
  std::ostringstream bytes;
  archive.save_to(bytes);
  std::filesystem::create_directories(options_.output_path);
  const std::string path =
      options_.output_path + "/checkpoint-" + std::to_string(step_) + ".pt";
  const std::string data = bytes.str();
  WriteFileAtomic(path, [&](std::ostream& out) { out.write(data.data(), data.size()); });
  // Keep the newest ones: if the newest is ever damaged, the previous one is still there.
  const auto all = ListCheckpoints(options_.output_path);
  for (size_t i = options_.keep_checkpoints; i < all.size(); ++i) {
    std::error_code ec;
    std::filesystem::remove(all[i].second, ec);
  }
  return path;
}

bool Trainer::LoadCheckpoint(const std::string& path, std::string* why) {
  try {
    const std::string data = ReadFileToString(path);
    torch::serialize::InputArchive archive;
    archive.load_from(data.data(), data.size(), device_);
    torch::Tensor format, step, seconds, config, sampler_state, rng;
    archive.read("format", format);
    if (format.item<int64_t>() != kCheckpointFormat) {
      *why = "unknown checkpoint format";
      return false;
    }
    archive.read("config", config);
    if (ModelConfig::FromJson(TensorString(config)).ToJson() != config_.ToJson()) {
      // Not corruption: the user asked for another network. Never silently mix.
      throw Error(path, "this checkpoint is of another network (" + TensorString(config) +
                            "); use another --output_path or the same --Train.variant");
    }
    archive.read("step", step);
    archive.read("train_seconds", seconds);
    archive.read("sampler_state", sampler_state);
    archive.read("torch_cpu_rng", rng);
    torch::serialize::InputArchive model, optimizer;
    archive.read("model", model);
    archive.read("optimizer", optimizer);
    // Into a fresh network first: a file that fails halfway leaves ours untouched.
    FvsNet loaded(config_);
    loaded->load(model);
    for (const auto& p : loaded->parameters()) {
      if (!torch::isfinite(p).all().item<bool>()) {
        *why = "the weights hold NaN or Inf";
        return false;
      }
    }
    {
      torch::NoGradGuard no_grad;
      auto dst = net_->parameters();
      auto src = loaded->parameters();
      for (size_t i = 0; i < dst.size(); ++i) dst[i].copy_(src[i].to(device_));
      auto dbuf = net_->buffers();
      auto sbuf = loaded->buffers();
      for (size_t i = 0; i < dbuf.size(); ++i) dbuf[i].copy_(sbuf[i].to(device_));
    }
    optimizer_->load(optimizer);
    // Adam's state keeps the step size it was saved with; the command line's wins, so
    // that a run can go on at a smaller one.
    for (auto& group : optimizer_->param_groups()) {
      static_cast<torch::optim::AdamOptions&>(group.options())
          .lr(options_.learning_rate);
    }
    sampler_->SetState(TensorString(sampler_state));
    {
      auto generator = at::detail::getDefaultCPUGenerator();
      std::lock_guard<std::mutex> lock(generator.mutex());
      generator.set_state(rng.to(torch::kCPU));
    }
    step_ = static_cast<int>(step.item<int64_t>());
    train_seconds_ = seconds.item<double>();
    return true;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    *why = what.substr(0, what.find('\n'));
    return false;
  }
}

void Trainer::Resume() {
  const auto checkpoints = ListCheckpoints(options_.output_path);
  std::vector<std::string> failures;
  for (const auto& [step, path] : checkpoints) {
    std::string why;
    if (LoadCheckpoint(path, &why)) {
      resumed_from_ = step_;
      if (!failures.empty() || !options_.quiet) {
        std::cerr << "[train] resumed from " << path << " (step " << step_ << ")\n";
      }
      return;
    }
    std::cerr << "[train] WARNING: " << path << " is unusable (" << why
              << "); falling back to the previous checkpoint\n";
    failures.push_back(path + " (" + why + ")");
  }
  if (!failures.empty()) {
    std::string list;
    for (const auto& f : failures) list += (list.empty() ? "" : "; ") + f;
    throw Error(options_.output_path, "no usable checkpoint to resume from: " + list +
                                          " (remove them to start afresh)");
  }
}

}  // namespace fvs
