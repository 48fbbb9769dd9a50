// Per-scene fine-tuning (`colmap view_synthesis_finetune`): adapts generic weights to one
// prepared workspace's own photos within a time budget. Leave-one-out on the scene's
// photos (a target is never among its own sources); the photos held out of the geometry
// (W/fvs/holdout.txt, prepare's --holdout_images) are never a target nor a source, so
// view_synthesis_eval --protocol holdout stays a test on unseen views. Files:
//   W/fvs/finetune/pack/        the scene packed at pack_scale (train/pack.h)
//   W/fvs/finetune/run/         the trainer's checkpoints (a rerun resumes; a larger
//                               budget trains on from where the last one stopped)
//   W/fvs/finetune/state.json   the initial weights' hash and the seconds spent packing
//   W/fvs/finetuned/<variant>.safetensors and .json: the result, which view_synthesis,
//                               view_synthesis_eval and the GUI use by default
//                               (SceneModelPath in render/fvs_method.h)
#pragma once

#include <string>

namespace fvs {

struct FinetuneOptions {
  std::string workspace_path;
  // Generic weights to start from. Empty: the shipped model of `variant`
  // (ShippedModelPath); when there is none, the variant's initial weights (fvs_agg
  // starts as the ULR blend), said on stderr.
  std::string model_path;
  std::string variant = "fvs_agg";
  // Wall-time budget of everything the command does (packing, loading, training);
  // training stops when what is left is spent.
  double minutes = 10;
  double pack_scale = 1.0;  // of the workspace images; 1 = the resolution renders use
  int num_sources = 5;
  int crop = 128;
  int batch_size = 4;
  double learning_rate = 1e-4;
  std::string loss = "auto";  // as view_synthesis_train's --Train.loss
  std::string lpips_path;     // empty: $FVS_LPIPS_PATH
  int num_threads = 0;        // <= 0: default
  int seed = 0;
  bool quiet = false;

  void Check() const;  // throws fvs::Error
};

struct FinetuneSummary {
  std::string model_path;  // W/fvs/finetuned/<variant>.safetensors
  std::string init_path;   // the weights started from ("" = the variant's initial ones)
  int steps = 0;           // optimiser steps of the run, all invocations
  double train_seconds = 0, pack_seconds = 0;
  bool interrupted = false;  // SIGINT/SIGTERM: checkpoint kept, no model written
};

// Throws fvs::Error for an unprepared workspace, unusable weights or too few photos.
FinetuneSummary RunFinetune(const FinetuneOptions& options);

}  // namespace fvs
