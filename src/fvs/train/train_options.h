// Options of the trainer (`colmap view_synthesis_train` and the standalone fvs_train_main
// share them) and the entry point. No torch here: the commands include this header only.
//
// The option parser is a minimal COLMAP-style `--key value` parser of its own because the
// trainer-only build (GPU machine) has no src/fvs/exe (OptionManager).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace fvs {

class OptionManager;

struct TrainOptions {
  std::string scene_list;      // file: one packed scene folder per line
  std::string output_path;     // M/: checkpoints, validation.csv, model.safetensors
  std::string val_scene_list;  // optional: held-out scenes for validation
  std::string vgg19_path;      // optional: VGG19 safetensors -> L1 + perceptual loss
  // Optional LPIPS weights (empty: $FVS_LPIPS_PATH, ResolveLpipsPath): validation reports
  // LPIPS, and the default loss becomes L1 + LPIPS.
  std::string lpips_path;
  // auto | l1+ssim | l1+lpips | l1+vgg19 (ChooseLoss in train/loss.h).
  std::string loss = "auto";
  double lpips_weight = 1.0;  // of the LPIPS term of l1+lpips
  // > 0: adds this times ChoiceLoss (train/loss.h) for soft-argmax networks: the blend
  // weights' expected per-source error, which teaches the per-pixel choice of a source.
  double choice_weight = 0;
  // Comma-separated parts of parameter names (e.g. "agg_confidence"): the parameters
  // whose names contain one keep their starting values (not trained, not in Adam's
  // state). A part that no name contains is an error. A resumed run must freeze the same
  // ones (Adam's state is of the trained parameters).
  std::string frozen;
  std::string variant = "fvs";
  // Start from these weights (their own variant and layout) instead of a fresh network;
  // a checkpoint in M still wins (resume). Fine-tuning (train/finetune.h) uses it.
  std::string init_weights;
  std::string device = "auto";  // auto | cpu | cuda
  // fp32 | bf16: bf16 runs each step's forward pass under autocast (convolutions in
  // bf16; fp32 master weights, gradients and Adam; the loss, LPIPS included, in fp32).
  // fp16 is not offered (it would need loss scaling). Validation stays fp32.
  std::string precision = "fp32";
  int max_steps = 100000;
  // > 0: also stop, writing the model as at max_steps, once the run's training time (all
  // invocations, the card's "hours") reaches this many minutes.
  double max_train_minutes = 0;
  int num_sources = 5;
  int crop = 192;
  // Pixels kept around the part of each source a target crop samples: the encoder runs
  // on that part only (CropSourcesToFootprint). -1: whole sources, as the paper.
  int source_margin = 16;
  int batch_size = 1;  // targets per optimiser step (gradients accumulated)
  double learning_rate = 1e-4;
  double checkpoint_minutes = 10;
  int checkpoint_every_steps = 0;  // > 0: also every N steps (tests, reproducibility)
  int keep_checkpoints = 2;
  int log_every = 10;
  int val_every = 1000;  // 0: no periodic validation (still at the end with a list)
  int val_views = 4;     // held-out views per validation scene
  // Train and validate on the views a scene holds out of its geometry (IsTargetView in
  // train/data.h): targets like novel views, whose own depth never built the mesh.
  bool holdout_targets = false;
  int seed = 0;
  bool augment = true;
  bool fp16_weights = false;
  double occlusion_tolerance = 0.01;  // warp validity, relative (reference: 1%)
  int num_threads = 0;                // CPU threads for LibTorch; <= 0: default
  bool quiet = false;                 // no progress lines (tests)
  // Only the trainer-only render benchmark (train/render_benchmark.h): renders
  // validation views of --val_scene_list with the network (--Train.init_weights, else a
  // fresh --Train.variant: timing only) and ulr, into M/render_benchmark.csv; no
  // training.
  bool benchmark = false;
  std::string bench_sizes = "480x270,960x540";      // WxH list
  std::string bench_ks = "1,2,3,4,5,6,7,8";         // K list, in the order run
  std::string bench_precisions = "fp32,bf16,fp16";  // fp16 skipped on the CPU
  double bench_seconds = 240;  // the grid's time bound (cells that would pass it skipped)
  int bench_views = 1;         // validation views per scene per cell
  // Tests: replaces the variant's layout with this JSON (ModelConfig::FromJson).
  std::string model_config_json;

  // Throws fvs::Error("view_synthesis_train", ...) for impossible values.
  void Check() const;
};

// The render benchmark's grid, parsed from TrainOptions::bench_*; throws fvs::Error on a
// malformed list.
struct BenchmarkGrid {
  std::vector<std::pair<int, int>> sizes;  // width, height
  std::vector<int> ks;
  std::vector<std::string> precisions;
};
BenchmarkGrid ParseBenchmarkGrid(const TrainOptions& options);

// Registers the trainer's options (`--scene_list L`, `--Train.max_steps N`, ...; the
// short `--max_steps` works too) bound to the fields of *o.
void AddTrainOptions(OptionManager* options, TrainOptions* o);

// Parses argv[first..argc) (first = 2 under the front door, 1 for fvs_train_main) and
// checks the result. Returns false when help was asked for (printed to stdout). Throws
// fvs::Error naming an unknown option, a missing or malformed value, a missing required
// option or a value Check() refuses.
bool ParseTrainOptions(int argc, char** argv, int first, TrainOptions* options);

// Reads a scene list: one folder per line; blank lines and lines starting with '#' are
// skipped; relative paths are relative to the list's folder. Throws fvs::Error
// "<list>:<line>: ..." for a folder that does not exist or has no scene.safetensors, and
// for an empty list.
std::vector<std::string> ReadSceneList(const std::string& list_path);

struct TrainSummary {
  int steps_done = 0;        // total steps of the run (resumed ones included)
  int resumed_from = -1;     // step of the checkpoint resumed from, -1 = fresh start
  double final_loss = 0;     // mean loss of the last logged window
  double seconds = 0;        // wall time of this invocation
  bool interrupted = false;  // stopped by SIGINT/SIGTERM (checkpoint written)
  std::string model_path;    // M/model.safetensors when max_steps was reached
};

// Trains (or resumes) as the options say. Throws fvs::Error on bad input.
TrainSummary RunTraining(const TrainOptions& options);

}  // namespace fvs
