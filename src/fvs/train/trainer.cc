#include "fvs/train/trainer.h"

#include <torch/version.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "fvs/net/image_tensor.h"
#include "fvs/net/lpips_weights.h"
#include "fvs/net/precision.h"
#include "fvs/train/packed_render.h"
#include "fvs/train/render_benchmark.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/hole_filling.h"
#include "fvs/util/machine.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

// The parameters Adam trains: all but those whose names contain one of the
// comma-separated parts of `frozen` (TrainOptions::frozen), which stop taking
// gradients. Names are the weights file's (module paths, e.g.
// agg_confidence.conv.weight).
std::vector<torch::Tensor> TrainedParameters(FvsNetImpl& net, const std::string& frozen) {
  std::vector<std::string> parts;
  for (const std::string& part : SplitString(frozen, ",")) {
    const std::string trimmed = TrimString(part);
    if (!trimmed.empty()) parts.push_back(trimmed);
  }
  std::vector<bool> used(parts.size(), false);
  std::vector<torch::Tensor> trained;
  for (auto& item : net.named_parameters()) {
    bool keep = true;
    for (size_t i = 0; i < parts.size(); ++i) {
      if (item.key().find(parts[i]) == std::string::npos) continue;
      used[i] = true;
      keep = false;
    }
    item.value().set_requires_grad(keep);
    if (keep) trained.push_back(item.value());
  }
  for (size_t i = 0; i < parts.size(); ++i) {
    Require(
        used[i], "view_synthesis_train",
        "--Train.frozen: no parameter name of this network contains '" + parts[i] + "'");
  }
  return trained;
}

volatile std::sig_atomic_t g_stop_requested = 0;
void RequestStop(int) { g_stop_requested = 1; }

// Restores the previous handlers when the loop ends (tests run several loops).
class StopSignals {
 public:
  StopSignals() {
    g_stop_requested = 0;
    old_int_ = std::signal(SIGINT, RequestStop);
    old_term_ = std::signal(SIGTERM, RequestStop);
  }
  ~StopSignals() {
    std::signal(SIGINT, old_int_);
    std::signal(SIGTERM, old_term_);
  }

 private:
  void (*old_int_)(int);
  void (*old_term_)(int);
};

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  std::ostringstream out;
  out << s / 3600 << "h" << std::setw(2) << std::setfill('0') << (s / 60) % 60 << "m"
      << std::setw(2) << s % 60 << "s";
  return out.str();
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

// The quality sums of a scene or of all scenes (ValidationResult and its Scene share
// the field names).
template <typename Sums>
void DivideSums(int views, Sums* s) {
  for (double* v :
       {&s->psnr, &s->ssim, &s->lpips, &s->ulr_psnr, &s->ulr_ssim, &s->ulr_lpips}) {
    *v /= views;
  }
}

// The card's figures of a scene or of all scenes.
template <typename Sums>
nlohmann::json QualityJson(const Sums& s, bool has_lpips) {
  nlohmann::json j = {{"psnr", s.psnr},
                      {"ssim", s.ssim},
                      {"ulr_psnr", s.ulr_psnr},
                      {"ulr_ssim", s.ulr_ssim},
                      {"seconds_per_view", s.seconds_per_view}};
  if (has_lpips) {
    j["lpips"] = s.lpips;
    j["ulr_lpips"] = s.ulr_lpips;
  }
  return j;
}

void AddSums(const ValidationResult::Scene& scene, ValidationResult* all) {
  all->psnr += scene.psnr;
  all->ssim += scene.ssim;
  all->lpips += scene.lpips;
  all->ulr_psnr += scene.ulr_psnr;
  all->ulr_ssim += scene.ulr_ssim;
  all->ulr_lpips += scene.ulr_lpips;
}

// M/validation.csv: the old rows and the new, written atomically.
void AppendValidationCsv(const std::string& folder, int step, int total_views,
                         const ValidationResult& result) {
  std::filesystem::create_directories(folder);
  const std::string csv = folder + "/validation.csv";
  std::string text;
  if (std::filesystem::exists(csv)) text = ReadFileToString(csv);
  const std::string header =
      "step,scene,views,psnr,ssim,seconds_per_view,ulr_psnr,ulr_ssim,lpips,ulr_lpips";
  if (text.empty()) text = header + "\n";
  // Files of older runs had fewer columns (no ULR, no LPIPS): the header names the
  // newest layout, their rows keep theirs.
  if (text.compare(0, header.size() + 1, header + "\n") != 0) {
    text = header + text.substr(std::min(text.find('\n'), text.size()));
  }
  std::ostringstream rows;
  rows << std::setprecision(6);
  auto lpips = [&](double v) {
    std::ostringstream s;
    s << std::setprecision(6) << v;
    return result.has_lpips ? s.str() : std::string("n/a");
  };
  for (const auto& r : result.scenes) {
    rows << step << "," << r.path << "," << r.views << "," << r.psnr << "," << r.ssim
         << "," << r.seconds_per_view << "," << r.ulr_psnr << "," << r.ulr_ssim << ","
         << lpips(r.lpips) << "," << lpips(r.ulr_lpips) << "\n";
  }
  rows << step << ",all," << total_views << "," << result.psnr << "," << result.ssim
       << "," << result.seconds_per_view << "," << result.ulr_psnr << ","
       << result.ulr_ssim << "," << lpips(result.lpips) << "," << lpips(result.ulr_lpips)
       << "\n";
  text += rows.str();
  WriteFileAtomic(csv, [&](std::ostream& out) { out << text; });
}

void PrintValidation(int step, int total_views, const ValidationResult& result) {
  std::ostringstream net, ulr;
  net << std::fixed << std::setprecision(2) << result.psnr << " dB, SSIM "
      << std::setprecision(4) << result.ssim;
  ulr << std::fixed << std::setprecision(2) << result.ulr_psnr << " dB, SSIM "
      << std::setprecision(4) << result.ulr_ssim;
  if (result.has_lpips) {
    net << ", LPIPS " << result.lpips;
    ulr << ", LPIPS " << result.ulr_lpips;
  }
  std::cerr << "[train] validation at step " << step << ": PSNR " << net.str() << ", "
            << std::fixed << std::setprecision(3) << result.seconds_per_view
            << " s/view (" << total_views
            << " views); ulr on the same views: " << ulr.str() << "\n";
}

// The best-model rule of M/best.safetensors: `a` beats `b` when its mean PSNR is not
// lower and its mean LPIPS lower, or its PSNR higher and its LPIPS not higher (SSIM in
// place of LPIPS without LPIPS weights). No weighting of one figure against another.
bool ValidationBeats(const ValidationResult& a, const ValidationResult& b) {
  const bool lpips = a.has_lpips && b.has_lpips;
  const double qa = lpips ? a.lpips : -a.ssim, qb = lpips ? b.lpips : -b.ssim;
  return (a.psnr >= b.psnr && qa < qb) || (a.psnr > b.psnr && qa <= qb);
}

// The validation figures of an earlier M/best.json (resume), if any.
bool ReadBestValidation(const std::string& folder, ValidationResult* best) {
  const std::string card = folder + "/best.json";
  if (!std::filesystem::is_regular_file(card)) return false;
  try {
    const nlohmann::json v =
        nlohmann::json::parse(ReadFileToString(card)).at("validation");
    best->step = v.at("step").get<int>();
    best->psnr = v.at("psnr").get<double>();
    best->ssim = v.at("ssim").get<double>();
    best->has_lpips = v.contains("lpips");
    if (best->has_lpips) best->lpips = v.at("lpips").get<double>();
    return true;
  } catch (const std::exception&) {
    return false;  // unreadable: the next validation writes a new one
  }
}

}  // namespace

Trainer::Trainer(const TrainOptions& options) : options_(options) {
  options_.Check();
  ConfigureTrainingThreads(options_);
  // Before the scenes: a bad weights file should not wait for them to load.
  net_ = InitialNetwork(options_, &config_);
  device_ = TrainingDevice(options_);
  dtype_ = PrecisionDtype(options_.precision, "--Train.precision");

  LoadLpipsWeights();

  const int k = options_.num_sources;
  train_scenes_ = LoadPackedScenes(options_.scene_list, k + 1, k);
  if (!options_.val_scene_list.empty()) {
    val_scenes_ = LoadPackedScenes(options_.val_scene_list, 2, k);
  }

  net_->to(device_);
  optimizer_ = std::make_unique<torch::optim::Adam>(
      TrainedParameters(*net_, options_.frozen),
      torch::optim::AdamOptions(options_.learning_rate));
  SamplerOptions sampler;
  sampler.num_sources = k;
  sampler.crop = options_.crop;
  sampler.augment = options_.augment;
  sampler.source_margin = options_.source_margin;
  sampler.holdout_targets = options_.holdout_targets;
  sampler.warp = SampleWarpOptionsFor(config_, options_.occlusion_tolerance);
  // A seed of its own stream: the sampler must not share draws with LibTorch.
  sampler_ = std::make_unique<TrainingSampler>(
      &train_scenes_, sampler,
      0x9E3779B97F4A7C15ULL ^ static_cast<uint64_t>(options_.seed));
  LossOptions loss;
  loss.kind = ChooseLoss(options_.loss, !options_.vgg19_path.empty(), !lpips_.is_empty());
  loss.vgg19_path = options_.vgg19_path;
  loss.lpips = lpips_;
  loss.lpips_weight = options_.lpips_weight;
  loss_ = std::make_unique<TrainingLoss>(loss, device_);
  Resume();
  has_best_ = ReadBestValidation(options_.output_path, &best_validation_);
}

void Trainer::LoadLpipsWeights() {
  lpips_path_ = ResolveLpipsPath(options_.lpips_path);
  if (lpips_path_.empty()) return;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(lpips_path_, ec)) {
    // Asked for by name: an error. Only a default (auto, perhaps from the environment):
    // the run goes on without LPIPS and says so.
    Require(!LossUsesLpips(options_.loss), lpips_path_,
            "no such file (the LPIPS weights of --Train.loss " + options_.loss + ")");
    std::cerr << "[train] WARNING: " << lpips_path_
              << ": no such file; no LPIPS in the loss or the validation\n";
    lpips_path_.clear();
    return;
  }
  lpips_ = LpipsNet(lpips_path_);  // a file that is not LPIPS weights throws
  lpips_->to(device_);
  lpips_->eval();
}

double Trainer::learning_rate() const {
  return static_cast<const torch::optim::AdamOptions&>(
             optimizer_->param_groups().front().options())
      .lr();
}

LossValue Trainer::Step() {
  net_->train();
  optimizer_->zero_grad();
  LossValue mean;
  const int b = options_.batch_size;
  for (int i = 0; i < b; ++i) {
    const DeviceSample s = ToDevice(sampler_->Next(), device_);
    BlendOutput out;
    {
      // --Train.precision bf16: the forward pass under autocast (convolutions in bf16,
      // fp32 master weights); the loss below in fp32, outside it.
      AutocastGuard autocast(device_, dtype_);
      out = net_->Forward(s.sources, s.grid, s.valid_depth, s.valid_warp,
                          s.ulr_log_weights);
    }
    out.rgb = out.rgb.to(torch::kFloat32);
    // Pixels no source sees are filled classically at render time (util/hole_filling.h):
    // the net is not asked to invent them (it would learn the training set's sky).
    const torch::Tensor seen = s.valid_warp.sum(0, true) > 0;
    const torch::Tensor prediction01 =
        torch::where(seen, (out.rgb + 1.0) * 0.5, s.target);
    LossValue loss = (*loss_)(prediction01, s.target);
    if (options_.choice_weight > 0 && out.weights.defined()) {
      const torch::Tensor choice =
          options_.choice_weight *
          ChoiceLoss(out.weights, out.per_source_rgb, s.target, seen);
      loss.total = loss.total + choice;
      loss.choice = choice.item<double>();
    }
    Require(std::isfinite(loss.l1) && std::isfinite(loss.second) &&
                std::isfinite(loss.choice),
            "view_synthesis_train",
            "the loss became NaN or Inf at step " + std::to_string(step_ + 1) +
                " (resume from the last checkpoint, perhaps with a lower learning rate)");
    (loss.total / b).backward();
    mean.l1 += loss.l1 / b;
    mean.second += loss.second / b;
    mean.choice += loss.choice / b;
  }
  optimizer_->step();
  ++step_;
  mean.total = torch::tensor(mean.Value());
  last_loss_ = mean.Value();
  return mean;
}

ValidationResult Trainer::Validate() {
  ValidationResult result;
  result.step = step_;
  result.has_lpips = !lpips_.is_empty();
  torch::NoGradGuard no_grad;
  net_->eval();
  SampleWarpOptions warp = SampleWarpOptionsFor(config_, options_.occlusion_tolerance);
  warp.ulr_log_weights = true;  // for the baseline, whatever the network
  int total_views = 0;
  for (const PackedScene& scene : val_scenes_) {
    ValidationResult::Scene r;
    r.path = scene.path;
    double seconds = 0;
    // By default the held-out views (view_synthesis_eval's) are never validated on;
    // with --Train.holdout_targets only they are (IsTargetView).
    for (const int target :
         ValidationTargets(scene, options_.val_views, options_.holdout_targets)) {
      const auto sources = SelectTrainingSources(scene, target, options_.num_sources);
      if (sources.empty()) continue;
      // Always fp32 (whatever --Train.precision): figures comparable across runs.
      const PackedViewRender v = RenderPackedView(net_, scene, target, sources, warp,
                                                  device_, torch::kFloat32, true);
      seconds += v.warp_s + v.network_s + v.rest_s;
      const ViewScores net = ScoreView(v.prediction, v.target, lpips_);
      const ViewScores base = ScoreView(v.ulr, v.target, lpips_);
      r.psnr += net.psnr;
      r.ssim += net.ssim;
      r.lpips += net.lpips;
      r.ulr_psnr += base.psnr;
      r.ulr_ssim += base.ssim;
      r.ulr_lpips += base.lpips;
      ++r.views;
    }
    if (r.views == 0) continue;
    AddSums(r, &result);
    result.seconds_per_view += seconds;
    total_views += r.views;
    DivideSums(r.views, &r);
    r.seconds_per_view = seconds / r.views;
    result.scenes.push_back(r);
  }
  net_->train();
  if (total_views > 0) {
    DivideSums(total_views, &result);
    result.seconds_per_view /= total_views;
  }
  AppendValidationCsv(options_.output_path, step_, total_views, result);
  if (!options_.quiet) PrintValidation(step_, total_views, result);
  last_validation_ = result;
  has_validation_ = true;
  if (total_views > 0 && (!has_best_ || ValidationBeats(result, best_validation_))) {
    best_validation_ = result;
    has_best_ = true;
    SaveModel("best");
    if (!options_.quiet) {
      std::cerr << "[train] best so far: " << options_.output_path
                << "/best.safetensors (step " << step_ << ")\n";
    }
  }
  return result;
}

std::string Trainer::HardwareDescription() const {
  std::ostringstream s;
  if (device_.is_cuda()) {
    s << "CUDA (" << torch::cuda::device_count() << " device(s) visible), host ";
  } else {
    s << "CPU, " << torch::get_num_threads() << " LibTorch threads, ";
  }
  s << std::thread::hardware_concurrency() << " cores, " << CpuModelName();
  return s.str();
}

std::string Trainer::SaveModel(const std::string& stem) {
  std::filesystem::create_directories(options_.output_path);
  const std::string path = options_.output_path + "/" + stem + ".safetensors";
  SaveWeights(net_, config_, path, options_.fp16_weights);
  nlohmann::json card;
  card["weights"] = stem + ".safetensors";
  if (!options_.init_weights.empty()) card["init_weights"] = options_.init_weights;
  card["variant"] = config_.variant;
  card["config"] = nlohmann::json::parse(config_.ToJson());
  card["loss"] = loss_->Name();
  if (LossUsesLpips(loss_->Name())) card["lpips_weight"] = options_.lpips_weight;
  if (options_.choice_weight > 0) card["choice_weight"] = options_.choice_weight;
  if (!options_.frozen.empty()) card["frozen"] = options_.frozen;
  if (!lpips_path_.empty()) card["lpips_weights"] = lpips_path_;
  card["steps"] = step_;
  card["batch_size"] = options_.batch_size;
  card["crop"] = options_.crop;
  card["precision"] = options_.precision;
  card["source_margin"] = options_.source_margin;
  card["num_sources"] = options_.num_sources;
  card["learning_rate"] = options_.learning_rate;
  card["seed"] = options_.seed;
  card["augment"] = options_.augment;
  card["hours"] = train_seconds_ / 3600.0;
  card["hardware"] = HardwareDescription();
  card["libtorch"] = std::to_string(TORCH_VERSION_MAJOR) + "." +
                     std::to_string(TORCH_VERSION_MINOR) + "." +
                     std::to_string(TORCH_VERSION_PATCH);
  card["written"] = UtcNow();
  card["final_loss"] = last_loss_;
  if (options_.max_train_minutes > 0)
    card["max_train_minutes"] = options_.max_train_minutes;
  auto scene_list = [](const std::vector<PackedScene>& scenes) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& s : scenes) {
      list.push_back({{"path", s.path},
                      {"views", s.num_views()},
                      {"width", s.width()},
                      {"height", s.height()}});
    }
    return list;
  };
  card["data"] = {{"train", scene_list(train_scenes_)},
                  {"validation", scene_list(val_scenes_)}};
  if (has_validation_) {
    nlohmann::json v = QualityJson(last_validation_, last_validation_.has_lpips);
    v["step"] = last_validation_.step;
    for (const auto& r : last_validation_.scenes) {
      nlohmann::json scene = QualityJson(r, last_validation_.has_lpips);
      scene["path"] = r.path;
      scene["views"] = r.views;
      v["scenes"].push_back(scene);
    }
    card["validation"] = v;
  }
  WriteFileAtomic(options_.output_path + "/" + stem + ".json",
                  [&](std::ostream& out) { out << card.dump(2) << "\n"; });
  return path;
}

TrainSummary Trainer::Run() {
  TrainSummary summary;
  summary.resumed_from = resumed_from_;
  Timer total;
  StopSignals signals;
  Timer since_checkpoint, window;
  double window_loss = 0, window_l1 = 0, window_second = 0, window_choice = 0;
  int window_steps = 0;
  const int first_step = step_;
  if (!options_.quiet) {
    std::cerr << "[train] " << config_.variant << " on " << HardwareDescription() << ", "
              << train_scenes_.size() << " scene(s), loss " << loss_->Name() << ", step "
              << step_ << " -> " << options_.max_steps << "\n";
  }
  const double budget_seconds = options_.max_train_minutes * 60;
  auto budget_spent = [&] {
    return budget_seconds > 0 && train_seconds_ >= budget_seconds;
  };
  while (step_ < options_.max_steps && !budget_spent()) {
    Timer step_timer;
    const LossValue loss = Step();
    train_seconds_ += step_timer.Seconds();
    window_loss += loss.Value();
    window_l1 += loss.l1;
    window_second += loss.second;
    window_choice += loss.choice;
    ++window_steps;
    if (step_ % options_.log_every == 0 || step_ == options_.max_steps ||
        budget_spent()) {
      const double rate = window_steps * options_.batch_size / window.Seconds();
      double eta =
          static_cast<double>(options_.max_steps - step_) * options_.batch_size / rate;
      if (budget_seconds > 0) eta = std::min(eta, budget_seconds - train_seconds_);
      summary.final_loss = window_loss / window_steps;
      if (!options_.quiet) {
        std::cerr << "[train] step " << step_ << "/" << options_.max_steps << "  loss "
                  << std::fixed << std::setprecision(4) << window_loss / window_steps
                  << " (l1 " << window_l1 / window_steps << ", "
                  << loss_->SecondTermName() << " " << window_second / window_steps;
        if (options_.choice_weight > 0)
          std::cerr << ", choice " << window_choice / window_steps;
        std::cerr << ")  " << std::setprecision(2) << rate << " samples/s  ETA "
                  << FormatDuration(eta) << "\n";
      }
      window_loss = window_l1 = window_second = window_choice = 0;
      window_steps = 0;
      window.Restart();
    }
    const bool periodic_checkpoint = options_.checkpoint_every_steps > 0 &&
                                     step_ % options_.checkpoint_every_steps == 0;
    if (periodic_checkpoint ||
        since_checkpoint.Seconds() >= options_.checkpoint_minutes * 60) {
      SaveCheckpoint();
      since_checkpoint.Restart();
    }
    if (!val_scenes_.empty() && options_.val_every > 0 &&
        step_ % options_.val_every == 0 && step_ < options_.max_steps) {
      Validate();
    }
    if (g_stop_requested) {
      const std::string path = SaveCheckpoint();
      std::cerr << "[train] interrupted at step " << step_ << "; checkpoint " << path
                << " (run again to resume)\n";
      summary.interrupted = true;
      break;
    }
  }
  if (!summary.interrupted) {
    if (window_steps > 0) summary.final_loss = window_loss / window_steps;
    if (step_ > first_step || ListCheckpoints(options_.output_path).empty())
      SaveCheckpoint();
    if (!val_scenes_.empty()) Validate();
    summary.model_path = SaveModel();
    if (!options_.quiet) {
      std::cerr << "[train] done: " << summary.model_path << " after " << step_
                << " steps (" << FormatDuration(train_seconds_) << " of training)\n";
    }
  }
  summary.steps_done = step_;
  summary.seconds = total.Seconds();
  return summary;
}

void ConfigureTrainingThreads(const TrainOptions& options) {
  if (options.num_threads > 0) {
    torch::set_num_threads(options.num_threads);
  } else {
    ConfigureTorchThreads();
  }
}

torch::Device TrainingDevice(const TrainOptions& options) {
  if (options.device == "cuda") {
    Require(torch::cuda::is_available(), "view_synthesis_train",
            "--Train.device cuda, but this LibTorch sees no CUDA device");
  }
  return (options.device == "cuda" ||
          (options.device == "auto" && torch::cuda::is_available()))
             ? torch::Device(torch::kCUDA)
             : torch::Device(torch::kCPU);
}

FvsNet InitialNetwork(const TrainOptions& options, ModelConfig* config) {
  if (!options.init_weights.empty()) {
    FvsNet net = LoadModel(options.init_weights, config);
    config->Check();
    // Seeded all the same: what draws from LibTorch's generator next (the training)
    // starts from --Train.seed either way.
    torch::manual_seed(static_cast<uint64_t>(options.seed));
    return net;
  }
  *config = options.model_config_json.empty()
                ? ModelConfig::ForVariant(options.variant)
                : ModelConfig::FromJson(options.model_config_json);
  config->Check();
  torch::manual_seed(static_cast<uint64_t>(options.seed));
  return FvsNet(*config);
}

TrainSummary RunTraining(const TrainOptions& options) {
  if (options.benchmark) return RunRenderBenchmark(options);
  return Trainer(options).Run();
}

}  // namespace fvs
