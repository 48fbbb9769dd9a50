// The training loop: packed scenes -> FvsNet weights. One Trainer per output folder M:
//   M/checkpoint-<step>.pt   model + Adam state + step + sampler RNG + torch RNG (atomic,
//                            the newest keep_checkpoints kept); the constructor resumes
//                            from the newest one that loads, falling back past corrupt
//                            ones
//   M/validation.csv         step, scene, views, PSNR, SSIM, seconds per view, the same
//                            of the ulr baseline, LPIPS of both (n/a without weights)
//   M/model.safetensors      final weights (SaveWeights) and M/model.json, its card
//   M/best.safetensors       the weights of the best validation so far and best.json
//                            (rule: ValidationBeats in trainer.cc; kept across resumes)
#pragma once

#include <torch/torch.h>

#include <memory>
#include <string>
#include <vector>

#include "fvs/net/net.h"
#include "fvs/train/data.h"
#include "fvs/train/loss.h"
#include "fvs/train/train_options.h"

namespace fvs {

// What a run starts from, one way for the trainer, fine-tuning (a Trainer with
// init_weights) and the render benchmark. LibTorch's threads: --Train.num_threads, else
// ConfigureTorchThreads. The device: --Train.device, cuda checked, auto CUDA where
// LibTorch sees one. The network: --Train.init_weights in the file's own layout whatever
// --Train.variant says, else a fresh --Train.variant (or model_config_json) initialised
// from --Train.seed; *config gets its layout, checked. Throw fvs::Error naming the
// option or the file.
void ConfigureTrainingThreads(const TrainOptions& options);
torch::Device TrainingDevice(const TrainOptions& options);
FvsNet InitialNetwork(const TrainOptions& options, ModelConfig* config);

struct ValidationResult {
  int step = 0;
  struct Scene {
    std::string path;
    int views = 0;
    double psnr = 0, ssim = 0, seconds_per_view = 0;
    // The `ulr` baseline on the same views, warps and masks (the ULR blend of the
    // warped sources, holes filled as the renderer fills them), for comparison.
    double ulr_psnr = 0, ulr_ssim = 0;
    double lpips = 0, ulr_lpips = 0;  // meaningful when has_lpips
  };
  std::vector<Scene> scenes;
  double psnr = 0, ssim = 0, seconds_per_view = 0;  // means over all views
  double ulr_psnr = 0, ulr_ssim = 0;
  double lpips = 0, ulr_lpips = 0;
  bool has_lpips = false;  // LPIPS weights were given (--lpips_path, FVS_LPIPS_PATH)
};

class Trainer {
 public:
  // Loads and checks the data, builds the network and Adam, resumes when M holds a
  // checkpoint. Throws fvs::Error on bad input (scene list, too few views, all
  // checkpoints corrupt, a checkpoint of another network).
  explicit Trainer(const TrainOptions& options);

  // One optimiser step over batch_size samples; returns the mean loss.
  LossValue Step();
  // Leave-one-out on the validation scenes at full packed size; appends validation.csv.
  ValidationResult Validate();
  // M/checkpoint-<step>.pt, atomically; removes all but the newest keep_checkpoints.
  std::string SaveCheckpoint();
  // Weights and card at M/<stem>.safetensors, M/<stem>.json.
  std::string SaveModel(const std::string& stem = "model");
  // The whole loop to max_steps with progress, checkpoints, validation; stops cleanly on
  // SIGINT / SIGTERM after writing a checkpoint.
  TrainSummary Run();

  // Replaces --Train.max_train_minutes (fine-tuning sets it once its setup is timed).
  void SetMaxTrainSeconds(double seconds) { options_.max_train_minutes = seconds / 60; }
  double train_seconds() const { return train_seconds_; }  // all invocations
  int step() const { return step_; }
  int resumed_from() const { return resumed_from_; }
  // Adam's step size now: --Train.learning_rate, also after a resume (a checkpoint's own
  // is replaced, so that a run can go on at a smaller one).
  double learning_rate() const;
  FvsNet& net() { return net_; }
  const ModelConfig& config() const { return config_; }
  const torch::Device& device() const { return device_; }

  // checkpoint-<step>.pt files of a folder, newest (highest step) first.
  static std::vector<std::pair<int, std::string>> ListCheckpoints(const std::string& dir);

 private:
  // Returns false (with the reason) when the file cannot be used.
  bool LoadCheckpoint(const std::string& path, std::string* why);
  // LPIPS weights of --lpips_path or FVS_LPIPS_PATH, for the loss and the validation.
  void LoadLpipsWeights();
  void Resume();
  std::string HardwareDescription() const;

  TrainOptions options_;
  ModelConfig config_;
  torch::Device device_ = torch::kCPU;
  torch::ScalarType dtype_ = torch::kFloat32;  // of the forward pass (--Train.precision)
  std::vector<PackedScene> train_scenes_, val_scenes_;
  FvsNet net_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;
  std::unique_ptr<TrainingSampler> sampler_;
  std::unique_ptr<TrainingLoss> loss_;
  LpipsNet lpips_{nullptr};  // empty without weights
  std::string lpips_path_;
  int step_ = 0;
  int resumed_from_ = -1;
  double train_seconds_ = 0;  // all invocations, for the card
  double last_loss_ = 0;
  ValidationResult last_validation_;
  bool has_validation_ = false;
  ValidationResult best_validation_;  // of M/best.safetensors
  bool has_best_ = false;
};

}  // namespace fvs
