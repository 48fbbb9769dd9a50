// colmap view_synthesis_finetune --workspace_path W --minutes M: adapts the shipped
// generic weights (or --model_path) to one prepared scene within M minutes of wall time,
// into W/fvs/finetuned/<variant>.safetensors, which view_synthesis, view_synthesis_eval
// and the GUI then use by default (train/finetune.h).
#include <iomanip>
#include <iostream>

#include "fvs/exe/command_registry.h"
#include "fvs/render/fvs_method.h"
#include "fvs/train/finetune.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunViewSynthesisFinetune(int argc, char** argv) {
  FinetuneOptions o;
  OptionManager options(
      "view_synthesis_finetune",
      "Fine-tune the generic network on one prepared scene's own photos "
      "within a time budget (photos held out at prepare are never used).");
  options.AddRequired("workspace_path", &o.workspace_path,
                      "prepared workspace (view_synthesis_prepare)");
  options.AddDefault("minutes", &o.minutes,
                     "wall-time budget of the whole command; rerun with more to go on");
  options.AddDefault("method", &o.variant, "network variant to fine-tune");
  options.AddDefault("model_path", &o.model_path,
                     "generic weights to start from (default: the shipped model)");
  options.AddDefault("lpips_path", &o.lpips_path,
                     "LPIPS weights for the loss (default $FVS_LPIPS_PATH)");
  options.AddDefault("Finetune.loss", &o.loss,
                     "auto | l1+ssim | l1+lpips | l1+ssim+lpips");
  options.AddDefault("Finetune.pack_scale", &o.pack_scale,
                     "image scale of the training copy of the scene (1 = as rendered)");
  options.AddDefault("Finetune.num_sources", &o.num_sources, "K sources per target");
  options.AddDefault("Finetune.crop", &o.crop, "square training crop in pixels");
  options.AddDefault("Finetune.batch_size", &o.batch_size, "crops per optimiser step");
  options.AddDefault("Finetune.learning_rate", &o.learning_rate, "Adam step size");
  options.AddDefault("Finetune.num_threads", &o.num_threads, "<= 0: all cores");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(o.workspace_path, "view_synthesis_finetune");
  if (o.model_path.empty()) o.model_path = ShippedModelPath(o.variant);
  const FinetuneSummary s = RunFinetune(o);
  if (s.interrupted) return 130;  // a checkpoint was written: run again to go on
  std::cerr << "fine-tuned model: " << s.model_path << " (" << s.steps << " steps, "
            << std::fixed << std::setprecision(0) << s.train_seconds << " s of training, "
            << s.pack_seconds << " s packing); view_synthesis and view_synthesis_eval on "
            << o.workspace_path << " now use it for --method " << o.variant << "\n";
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND(
    "view_synthesis_finetune",
    "fine-tune the network on one scene within a time budget (resumable)",
    RunViewSynthesisFinetune);

}  // namespace fvs
