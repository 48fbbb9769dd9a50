#include "fvs/train/train_options.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "fvs/util/error.h"
#include "fvs/util/parse_int.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

const char kSubject[] = "view_synthesis_train";

enum class Kind { kString, kInt, kDouble, kBool };

struct OptionSpec {
  std::string name;  // as documented (with "Train." for the tuning knobs)
  Kind kind;
  void* target;
  bool required;
  std::string help;
};

std::vector<OptionSpec> Specs(TrainOptions* o) {
  return {
      {"scene_list", Kind::kString, &o->scene_list, true,
       "file listing packed scene folders (view_synthesis_pack), one per line"},
      {"output_path", Kind::kString, &o->output_path, true,
       "folder for checkpoints, validation.csv, model.safetensors, model.json"},
      {"val_scene_list", Kind::kString, &o->val_scene_list, false,
       "packed scenes held out for validation (optional)"},
      {"vgg19_path", Kind::kString, &o->vgg19_path, false,
       "VGG19 weights (.safetensors): L1 + perceptual loss instead of L1 + SSIM"},
      {"lpips_path", Kind::kString, &o->lpips_path, false,
       "LPIPS weights (.safetensors; default $FVS_LPIPS_PATH): validation reports LPIPS "
       "and the default loss is L1 + LPIPS"},
      {"Train.loss", Kind::kString, &o->loss, false,
       "auto (l1+vgg19 with --vgg19_path, else l1+lpips with LPIPS weights, else "
       "l1+ssim), l1+ssim, l1+lpips, l1+ssim+lpips or l1+vgg19"},
      {"Train.lpips_weight", Kind::kDouble, &o->lpips_weight, false,
       "weight of the LPIPS term of l1+lpips and l1+ssim+lpips"},
      {"Train.variant", Kind::kString, &o->variant, false, "network variant"},
      {"Train.init_weights", Kind::kString, &o->init_weights, false,
       "start from these weights (.safetensors; their variant) instead of a fresh "
       "network (a checkpoint in the output folder still resumes first)"},
      {"Train.max_train_minutes", Kind::kDouble, &o->max_train_minutes, false,
       "> 0: also stop and write the model once the training time of all invocations "
       "reaches this"},
      {"Train.device", Kind::kString, &o->device, false, "auto | cpu | cuda"},
      {"Train.precision", Kind::kString, &o->precision, false,
       "fp32 | bf16: bf16 runs the forward pass under autocast (fp32 weights, "
       "gradients, optimiser and loss)"},
      {"Train.max_steps", Kind::kInt, &o->max_steps, false, "optimiser steps in all"},
      {"Train.num_sources", Kind::kInt, &o->num_sources, false,
       "K: sources per target (top-K by overlap)"},
      {"Train.crop", Kind::kInt, &o->crop, false, "square target crop in pixels"},
      {"Train.source_margin", Kind::kInt, &o->source_margin, false,
       "encode only the part of each source the crop samples, plus this margin in "
       "pixels (-1: whole sources)"},
      {"Train.batch_size", Kind::kInt, &o->batch_size, false,
       "targets per optimiser step (gradients accumulated)"},
      {"Train.learning_rate", Kind::kDouble, &o->learning_rate, false, "Adam step size"},
      {"Train.checkpoint_minutes", Kind::kDouble, &o->checkpoint_minutes, false,
       "minutes between checkpoints"},
      {"Train.checkpoint_every_steps", Kind::kInt, &o->checkpoint_every_steps, false,
       "also a checkpoint every N steps (0: off)"},
      {"Train.keep_checkpoints", Kind::kInt, &o->keep_checkpoints, false,
       "checkpoints kept (newest first)"},
      {"Train.log_every", Kind::kInt, &o->log_every, false,
       "steps between progress lines"},
      {"Train.val_every", Kind::kInt, &o->val_every, false,
       "steps between validation passes (0: only at the end)"},
      {"Train.val_views", Kind::kInt, &o->val_views, false,
       "held-out views per validation scene"},
      {"Train.seed", Kind::kInt, &o->seed, false, "seed of initialisation and sampling"},
      {"Train.augment", Kind::kBool, &o->augment, false, "photometric augmentation"},
      {"Train.fp16_weights", Kind::kBool, &o->fp16_weights, false,
       "write model.safetensors in fp16"},
      {"Train.occlusion_tolerance", Kind::kDouble, &o->occlusion_tolerance, false,
       "relative depth tolerance of a valid warp"},
      {"Train.headroom", Kind::kBool, &o->headroom, false,
       "only measure ulr and the per-pixel and global oracles on the validation "
       "views (M/headroom.csv), no training"},
      {"Train.benchmark", Kind::kBool, &o->benchmark, false,
       "only the render benchmark: validation views of --val_scene_list rendered at "
       "--Train.bench_sizes, K in --Train.bench_ks, --Train.bench_precisions "
       "(M/render_benchmark.csv); weights of --Train.init_weights, else a fresh network"},
      {"Train.bench_sizes", Kind::kString, &o->bench_sizes, false,
       "render benchmark: WxH sizes, comma separated"},
      {"Train.bench_ks", Kind::kString, &o->bench_ks, false,
       "render benchmark: numbers of sources, comma separated, in the order run"},
      {"Train.bench_precisions", Kind::kString, &o->bench_precisions, false,
       "render benchmark: fp32, bf16, fp16 (fp16 on CUDA only)"},
      {"Train.bench_seconds", Kind::kDouble, &o->bench_seconds, false,
       "render benchmark: time bound; cells that would pass it are skipped"},
      {"Train.bench_views", Kind::kInt, &o->bench_views, false,
       "render benchmark: validation views per scene in each cell"},
      {"Train.num_threads", Kind::kInt, &o->num_threads, false,
       "LibTorch CPU threads (<= 0: FVS_NUM_THREADS or all cores)"},
  };
}

bool ParseBool(const std::string& v, bool* out) {
  if (v == "1" || v == "true" || v == "on" || v == "yes") return *out = true, true;
  if (v == "0" || v == "false" || v == "off" || v == "no") return *out = false, true;
  return false;
}

void Assign(const OptionSpec& spec, const std::string& value) {
  const std::string what = "--" + spec.name + " " + value;
  try {
    size_t used = 0;
    switch (spec.kind) {
      case Kind::kString:
        *static_cast<std::string*>(spec.target) = value;
        return;
      case Kind::kInt: {
        const long long v = std::stoll(value, &used);
        if (used != value.size() || v < -2147483648LL || v > 2147483647LL) break;
        *static_cast<int*>(spec.target) = static_cast<int>(v);
        return;
      }
      case Kind::kDouble: {
        const double v = std::stod(value, &used);
        if (used != value.size() || !std::isfinite(v)) break;
        *static_cast<double*>(spec.target) = v;
        return;
      }
      case Kind::kBool:
        if (ParseBool(value, static_cast<bool*>(spec.target))) return;
        break;
    }
  } catch (const std::exception&) {
  }
  throw Error(kSubject, "cannot parse the value of " + what);
}

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

std::string TrainUsage(const std::string& program) {
  TrainOptions defaults;
  std::ostringstream s;
  s << "Usage: " << program << " --scene_list L --output_path M [options]\n"
    << "Trains the view-synthesis network on packed scenes (view_synthesis_pack); a run\n"
    << "resumes from the newest valid checkpoint in M.\n\nOptions:\n";
  TrainOptions tmp = defaults;
  for (const OptionSpec& spec : Specs(&tmp)) {
    s << "  --" << spec.name;
    switch (spec.kind) {
      case Kind::kString:
        s << " <text>";
        if (!static_cast<std::string*>(spec.target)->empty())
          s << " (default " << *static_cast<std::string*>(spec.target) << ")";
        break;
      case Kind::kInt:
        s << " <int> (default " << *static_cast<int*>(spec.target) << ")";
        break;
      case Kind::kDouble:
        s << " <number> (default " << *static_cast<double*>(spec.target) << ")";
        break;
      case Kind::kBool:
        s << " <0|1> (default " << *static_cast<bool*>(spec.target) << ")";
        break;
    }
    s << (spec.required ? " [required]" : "") << "\n      " << spec.help << "\n";
  }
  return s.str();
}

bool ParseTrainOptions(int argc, char** argv, int first, TrainOptions* options) {
  std::vector<OptionSpec> specs = Specs(options);
  std::vector<bool> seen(specs.size(), false);
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::string program = argc > 0 ? argv[0] : "fvs_train_main";
      if (first >= 2 && argc > 1) program += std::string(" ") + argv[1];
      std::cout << TrainUsage(program);
      return false;
    }
    Require(StartsWith(arg, "--") && arg.size() > 2, kSubject,
            "unexpected argument '" + arg + "' (options are --name value)");
    std::string name = arg.substr(2);
    std::string value;
    bool has_value = false;
    const size_t eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    size_t k = 0;
    // "Train.x" and bare "x" both name option x.
    for (; k < specs.size(); ++k) {
      const std::string& n = specs[k].name;
      if (n == name || (StartsWith(n, "Train.") && n.substr(6) == name) ||
          ("Train." + n) == name) {
        break;
      }
    }
    Require(k < specs.size(), kSubject, "unknown option --" + name);
    if (!has_value) {
      Require(i + 1 < argc, kSubject, "option --" + name + " needs a value");
      value = argv[++i];
    }
    Assign(specs[k], value);
    seen[k] = true;
  }
  for (size_t k = 0; k < specs.size(); ++k) {
    Require(!specs[k].required || seen[k], kSubject,
            "missing required option --" + specs[k].name);
  }
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
