#include "fvs/train/train_options.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "fvs/util/error.h"
#include "fvs/util/option_manager.h"
#include "fvs/util/parse_int.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

const char kSubject[] = "view_synthesis_train";

}  // namespace

void TrainOptions::Check() const {
  Require(!scene_list.empty(), kSubject, "--scene_list is required");
  Require(!output_path.empty(), kSubject, "--output_path is required");
  Require(max_steps > 0, kSubject, "--Train.max_steps must be positive");
  Require(max_train_minutes >= 0, kSubject, "--Train.max_train_minutes must be >= 0");
  Require(num_sources >= 1, kSubject, "--Train.num_sources must be at least 1");
  Require(crop >= 16, kSubject, "--Train.crop must be at least 16 (SSIM window)");
  Require(batch_size >= 1, kSubject, "--Train.batch_size must be at least 1");
  Require(source_margin >= -1, kSubject, "--Train.source_margin must be >= -1");
  Require(learning_rate > 0, kSubject, "--Train.learning_rate must be positive");
  Require(checkpoint_minutes > 0, kSubject,
          "--Train.checkpoint_minutes must be positive");
  Require(checkpoint_every_steps >= 0, kSubject,
          "--Train.checkpoint_every_steps must be >= 0");
  Require(keep_checkpoints >= 2, kSubject,
          "--Train.keep_checkpoints must be at least 2 (a corrupt newest falls back)");
  Require(log_every >= 1, kSubject, "--Train.log_every must be at least 1");
  Require(val_every >= 0, kSubject, "--Train.val_every must be >= 0");
  Require(val_views >= 1, kSubject, "--Train.val_views must be at least 1");
  Require(occlusion_tolerance > 0, kSubject, "--Train.occlusion_tolerance must be > 0");
  Require(device == "auto" || device == "cpu" || device == "cuda", kSubject,
          "--Train.device must be auto, cpu or cuda");
  Require(
      loss == "auto" || loss == "l1+ssim" || loss == "l1+lpips" ||
          loss == "l1+ssim+lpips" || loss == "l1+vgg19",
      kSubject,
      "--Train.loss must be auto, l1+ssim, l1+lpips, l1+ssim+lpips or l1+vgg19, not '" +
          loss + "'");
  Require(loss != "l1+vgg19" || !vgg19_path.empty(), kSubject,
          "--Train.loss l1+vgg19 needs --vgg19_path");
  Require(lpips_weight > 0, kSubject, "--Train.lpips_weight must be positive");
  Require(choice_weight >= 0, kSubject, "--Train.choice_weight must not be negative");
  Require(precision == "fp32" || precision == "bf16", kSubject,
          "--Train.precision must be fp32 or bf16, not '" + precision +
              "' (fp16 training would need loss scaling)");
  if (benchmark) {
    Require(!val_scene_list.empty(), kSubject,
            "--Train.benchmark needs --val_scene_list");
    Require(bench_seconds > 0, kSubject, "--Train.bench_seconds must be positive");
    Require(bench_views >= 1, kSubject, "--Train.bench_views must be at least 1");
    ParseBenchmarkGrid(*this);  // throws on a malformed list
  }
}

BenchmarkGrid ParseBenchmarkGrid(const TrainOptions& o) {
  auto split = [](const std::string& list) {
    std::vector<std::string> items;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
      item = TrimString(item);
      if (!item.empty()) items.push_back(item);
    }
    return items;
  };
  auto to_int = [](const std::string& s, const std::string& what) {
    int v = 0;
    Require(ParsePositiveInt(s, &v), kSubject,
            what + ": '" + s + "' is not a positive whole number");
    return v;
  };
  BenchmarkGrid grid;
  for (const std::string& s : split(o.bench_sizes)) {
    const size_t x = s.find('x');
    Require(x != std::string::npos, kSubject,
            "--Train.bench_sizes: '" + s + "' is not WxH");
    grid.sizes.push_back({to_int(s.substr(0, x), "--Train.bench_sizes"),
                          to_int(s.substr(x + 1), "--Train.bench_sizes")});
  }
  for (const std::string& s : split(o.bench_ks)) {
    grid.ks.push_back(to_int(s, "--Train.bench_ks"));
  }
  for (const std::string& s : split(o.bench_precisions)) {
    Require(s == "fp32" || s == "bf16" || s == "fp16", kSubject,
            "--Train.bench_precisions: '" + s + "' must be fp32, bf16 or fp16");
    grid.precisions.push_back(s);
  }
  Require(!grid.sizes.empty() && !grid.ks.empty() && !grid.precisions.empty(), kSubject,
          "--Train.benchmark needs at least one size, K and precision");
  return grid;
}

void AddTrainOptions(OptionManager* options, TrainOptions* o) {
  options->AddRequired(
      "scene_list", &o->scene_list,
      "file listing packed scene folders (view_synthesis_pack), one per line");
  options->AddRequired(
      "output_path", &o->output_path,
      "folder for checkpoints, validation.csv, model.safetensors, model.json");
  options->AddDefault("val_scene_list", &o->val_scene_list,
                      "packed scenes held out for validation (optional)");
  options->AddDefault(
      "vgg19_path", &o->vgg19_path,
      "VGG19 weights (.safetensors): L1 + perceptual loss instead of L1 + SSIM");
  options->AddDefault(
      "lpips_path", &o->lpips_path,
      "LPIPS weights (.safetensors; default $FVS_LPIPS_PATH): validation reports LPIPS "
      "and the default loss is L1 + LPIPS");
  options->AddDefault(
      "Train.loss", &o->loss,
      "auto (l1+vgg19 with --vgg19_path, else l1+lpips with LPIPS weights, else "
      "l1+ssim), l1+ssim, l1+lpips, l1+ssim+lpips or l1+vgg19");
  options->AddDefault("Train.lpips_weight", &o->lpips_weight,
                      "weight of the LPIPS term of l1+lpips and l1+ssim+lpips");
  options->AddDefault("Train.choice_weight", &o->choice_weight,
                      "weight of the choice term (the blend weights' expected "
                      "per-source error; soft-argmax networks; 0 = off)");
  options->AddDefault("Train.frozen", &o->frozen,
                      "parameters whose names contain one of these comma-separated "
                      "parts keep their starting values (e.g. agg_confidence: the "
                      "ULR weights choose the sources, the rest trains)");
  options->AddDefault("Train.variant", &o->variant, "network variant");
  options->AddDefault(
      "Train.init_weights", &o->init_weights,
      "start from these weights (.safetensors; their variant) instead of a fresh "
      "network (a checkpoint in the output folder still resumes first)");
  options->AddDefault(
      "Train.max_train_minutes", &o->max_train_minutes,
      "> 0: also stop and write the model once the training time of all invocations "
      "reaches this");
  options->AddDefault("Train.device", &o->device, "auto | cpu | cuda");
  options->AddDefault(
      "Train.precision", &o->precision,
      "fp32 | bf16: bf16 runs the forward pass under autocast (fp32 weights, "
      "gradients, optimiser and loss)");
  options->AddDefault("Train.max_steps", &o->max_steps, "optimiser steps in all");
  options->AddDefault("Train.num_sources", &o->num_sources,
                      "K: sources per target (top-K by overlap)");
  options->AddDefault("Train.crop", &o->crop, "square target crop in pixels");
  options->AddDefault(
      "Train.source_margin", &o->source_margin,
      "encode only the part of each source the crop samples, plus this margin in "
      "pixels (-1: whole sources)");
  options->AddDefault("Train.batch_size", &o->batch_size,
                      "targets per optimiser step (gradients accumulated)");
  options->AddDefault("Train.learning_rate", &o->learning_rate, "Adam step size");
  options->AddDefault("Train.checkpoint_minutes", &o->checkpoint_minutes,
                      "minutes between checkpoints");
  options->AddDefault("Train.checkpoint_every_steps", &o->checkpoint_every_steps,
                      "also a checkpoint every N steps (0: off)");
  options->AddDefault("Train.keep_checkpoints", &o->keep_checkpoints,
                      "checkpoints kept (newest first)");
  options->AddDefault("Train.log_every", &o->log_every, "steps between progress lines");
  options->AddDefault("Train.val_every", &o->val_every,
                      "steps between validation passes (0: only at the end)");
  options->AddDefault("Train.val_views", &o->val_views,
                      "held-out views per validation scene");
  options->AddDefault("Train.holdout_targets", &o->holdout_targets,
                      "a scene that holds views out of its geometry trains and "
                      "validates on those only (targets like novel views)");
  options->AddDefault("Train.seed", &o->seed, "seed of initialisation and sampling");
  options->AddDefault("Train.augment", &o->augment, "photometric augmentation");
  options->AddDefault("Train.fp16_weights", &o->fp16_weights,
                      "write model.safetensors in fp16");
  options->AddDefault("Train.occlusion_tolerance", &o->occlusion_tolerance,
                      "relative depth tolerance of a valid warp");
  options->AddDefault(
      "Train.benchmark", &o->benchmark,
      "only the render benchmark: validation views of --val_scene_list rendered at "
      "--Train.bench_sizes, K in --Train.bench_ks, --Train.bench_precisions "
      "(M/render_benchmark.csv); weights of --Train.init_weights, else a fresh network");
  options->AddDefault("Train.bench_sizes", &o->bench_sizes,
                      "render benchmark: WxH sizes, comma separated");
  options->AddDefault(
      "Train.bench_ks", &o->bench_ks,
      "render benchmark: numbers of sources, comma separated, in the order run");
  options->AddDefault("Train.bench_precisions", &o->bench_precisions,
                      "render benchmark: fp32, bf16, fp16 (fp16 on CUDA only)");
  options->AddDefault(
      "Train.bench_seconds", &o->bench_seconds,
      "render benchmark: time bound; cells that would pass it are skipped");
  options->AddDefault("Train.bench_views", &o->bench_views,
                      "render benchmark: validation views per scene in each cell");
  options->AddDefault("Train.num_threads", &o->num_threads,
                      "LibTorch CPU threads (<= 0: FVS_NUM_THREADS or all cores)");
}

bool ParseTrainOptions(int argc, char** argv, int first, TrainOptions* options) {
  OptionManager manager(kSubject,
                        "Trains the view-synthesis network on packed scenes "
                        "(view_synthesis_pack); a run resumes from the newest valid "
                        "checkpoint in --output_path.");
  // The standalone trainer (first == 1) is its own program.
  if (first < 2) {
    manager.SetProgram(argc > 0 ? std::filesystem::path(argv[0]).filename().string()
                                : "fvs_train_main");
  }
  AddTrainOptions(&manager, options);
  if (!manager.Parse(argc, argv, first)) return false;
  options->Check();
  return true;
}

std::vector<std::string> ReadSceneList(const std::string& list_path) {
  namespace fs = std::filesystem;
  std::ifstream in(list_path);
  Require(static_cast<bool>(in), list_path, "cannot read the scene list");
  const fs::path base = fs::path(list_path).parent_path();
  std::vector<std::string> scenes;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string entry = TrimString(line);
    if (entry.empty() || entry[0] == '#') continue;
    fs::path p(entry);
    if (p.is_relative()) p = base / p;
    const std::string where = list_path + ":" + std::to_string(number);
    std::error_code ec;
    Require(fs::is_directory(p, ec), where,
            "scene folder '" + p.string() + "' does not exist");
    Require(fs::is_regular_file(p / "scene.safetensors", ec), where,
            "'" + p.string() +
                "' is not a packed scene (no scene.safetensors; run colmap "
                "view_synthesis_pack on its workspace)");
    scenes.push_back(p.lexically_normal().string());
  }
  Require(!scenes.empty(), list_path, "the scene list names no scene");
  return scenes;
}

}  // namespace fvs
