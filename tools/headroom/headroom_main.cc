// fvs_headroom_main: what a blender could still gain on packed validation scenes
// (tools/headroom/headroom.h): `ulr`, the oracles that see the target photo (per pixel,
// per 8x8 block, global, colour), the photo-free blends (consensus, alignment, exposure,
// depth sweep and stereo) and, with --choice, per-pixel choice models fitted on the
// --scene_list targets. A measurement instrument beside the product: it writes
// <output_path>/headroom.csv and prints the rows; doc/training.md has what it found.
//
//   fvs_headroom_main --val_scene_list L --output_path O [--methods ulr,oracle_patch8]
//                     [--scene_list T --choice 0:l1:all,16:l2:local] [--holdout_targets
//                     1]
#include <torch/torch.h>

#include <csignal>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "fvs/net/lpips_net.h"
#include "fvs/net/lpips_weights.h"
#include "fvs/net/net.h"
#include "fvs/train/data.h"
#include "fvs/train/train_options.h"
#include "fvs/util/error.h"
#include "fvs/util/option_manager.h"
#include "tools/headroom/choice_evidence.h"
#include "tools/headroom/headroom.h"

namespace fvs {
namespace {

struct HeadroomOptions {
  std::string val_scene_list;  // the scenes measured
  std::string scene_list;      // the scenes --choice models are fitted on
  std::string output_path;
  std::string lpips_path;       // empty: $FVS_LPIPS_PATH
  std::string variant = "fvs";  // view_synthesis_train's default, as measured before
  int num_sources = 5;
  int val_views = 4;
  bool holdout_targets = false;
  double occlusion_tolerance = 0.01;
  std::string choice;   // HIDDEN:l1|l2:all|local,... (ParseChoiceSpecs)
  std::string methods;  // comma-separated prefixes of the rows; empty = all
  int seed = 0;
  int num_threads = 0;
  bool quiet = false;
};

bool Parse(int argc, char** argv, HeadroomOptions* o) {
  OptionManager options("fvs_headroom_main",
                        "Measure ulr, the oracles and the photo-free blends on packed "
                        "validation scenes (M/headroom.csv).");
  options.SetProgram("fvs_headroom_main");
  options.AddRequired("val_scene_list", &o->val_scene_list,
                      "packed scenes to measure (one folder per line)");
  options.AddRequired("output_path", &o->output_path, "folder for headroom.csv");
  options.AddDefault("scene_list", &o->scene_list,
                     "packed scenes the --choice models are fitted on");
  options.AddDefault("lpips_path", &o->lpips_path,
                     "LPIPS weights (default $FVS_LPIPS_PATH; none: no LPIPS column)");
  options.AddDefault("variant", &o->variant, "network variant whose warp is measured");
  options.AddDefault("num_sources", &o->num_sources, "K sources per view");
  options.AddDefault("val_views", &o->val_views, "views per validation scene");
  options.AddDefault("holdout_targets", &o->holdout_targets,
                     "only the views each scene holds out of its geometry");
  options.AddDefault("occlusion_tolerance", &o->occlusion_tolerance,
                     "relative depth tolerance of a valid warp");
  options.AddDefault("choice", &o->choice,
                     "per-pixel choice models as rows: HIDDEN:l1|l2:all|local,... "
                     "(e.g. 0:l1:all,16:l2:local; needs --scene_list)");
  options.AddDefault("methods", &o->methods,
                     "only the rows whose names start with one of these "
                     "comma-separated prefixes (empty = all)");
  options.AddDefault("seed", &o->seed, "seed of the choice fits");
  options.AddDefault("num_threads", &o->num_threads, "LibTorch threads (0: default)");
  options.AddDefault("quiet", &o->quiet, "no progress lines");
  return options.Parse(argc, argv, 1);
}

ImageDistance LpipsDistance(const std::string& flag) {
  const std::string path = ResolveLpipsPath(flag);
  if (path.empty()) return nullptr;
  LpipsNet lpips(path);
  lpips->eval();
  return [lpips](const torch::Tensor& a, const torch::Tensor& b) mutable {
    torch::NoGradGuard no_grad;
    return lpips->forward(a, b).item<double>();
  };
}

// The fitted choice models of --choice, printed with their errors (and, for a linear
// one, the weight of each evidence channel: what it keys on).
std::vector<NamedChoiceModel> FitChoices(const HeadroomOptions& o,
                                         const SampleWarpOptions& warp) {
  const std::vector<ChoiceFitOptions> fits = ParseChoiceSpecs(o.choice);
  if (fits.empty()) return {};
  Require(!o.scene_list.empty(), "--choice", "needs --scene_list (the fitted scenes)");
  const std::vector<PackedScene> scenes =
      LoadPackedScenes(o.scene_list, 2, o.num_sources);
  std::vector<NamedChoiceModel> models;
  for (ChoiceFitOptions fit : fits) {
    fit.seed = static_cast<uint64_t>(o.seed) + 1;
    const ChoiceFit result =
        FitChoiceModel(scenes, o.num_sources, warp, o.holdout_targets, fit, o.quiet);
    const std::string name = ChoiceSpecName(fit);
    std::cout << name << ": error " << result.start_error << " (ulr) -> "
              << result.final_error << " on " << result.pixels
              << " pixels of the --scene_list targets\n";
    if (fit.hidden == 0) {
      const torch::Tensor weight = result.model->first->weight.flatten();
      for (int c = 0; c < kNumEvidence; ++c) {
        std::cout << "  " << EvidenceChannelName(c) << " " << weight[c].item<double>()
                  << "\n";
      }
    }
    models.push_back({name, result.model});
  }
  return models;
}

int Run(int argc, char** argv) {
  HeadroomOptions o;
  if (!Parse(argc, argv, &o)) return 0;
  ConfigureTorchThreads();
  if (o.num_threads > 0) torch::set_num_threads(o.num_threads);
  const SampleWarpOptions warp =
      SampleWarpOptionsFor(ModelConfig::ForVariant(o.variant), o.occlusion_tolerance);
  const ImageDistance distance = LpipsDistance(o.lpips_path);
  const std::vector<NamedChoiceModel> choice = FitChoices(o, warp);
  const std::vector<HeadroomRow> rows =
      MeasureHeadroom(LoadPackedScenes(o.val_scene_list, 2, o.num_sources), o.num_sources,
                      o.val_views, warp, distance, o.holdout_targets, choice, o.methods);
  std::filesystem::create_directories(o.output_path);
  WriteHeadroomCsv(o.output_path + "/headroom.csv", rows);
  for (const HeadroomRow& r : rows) {
    std::cout << r.scene << "  " << r.method << "  " << r.views << " views  PSNR "
              << std::fixed << std::setprecision(2) << r.psnr << "  SSIM "
              << std::setprecision(4) << r.ssim;
    if (r.lpips >= 0) std::cout << "  LPIPS " << r.lpips;
    std::cout << "\n";
  }
  return 0;
}

}  // namespace
}  // namespace fvs

int main(int argc, char** argv) {
  std::signal(SIGXFSZ, SIG_IGN);  // a full disk is a write error, not a silent kill
  try {
    return fvs::Run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "ERROR: " << e.what() << "\n";
    return 1;
  }
}
