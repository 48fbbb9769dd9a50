// colmap view_synthesis_eval --workspace_path W --output_path O
//   protocol: --protocol auto|holdout|leave_one_out|subsequence|indices (--every N,
//             --subsequence START:LENGTH, --target_indices 0,5 / --target_names a.png)
//   one configuration: --method, --model_path, --num_sources K, --scale s
//   or --sweep 1: methods x K x scales x precisions (--sweep_* lists)
//   --shard i/n: only every n-th target (merge with view_synthesis_eval_merge)
//   --lpips_path: LPIPS weights (safetensors; default $FVS_LPIPS_PATH); without them
//                 LPIPS is "n/a"
// Renders the protocol's targets, scores them against the photos and writes the reports:
// RunEvaluation (controllers/evaluation.h) does the work and states what is written. The
// exit status is 1 when any view failed.
#include "fvs/controllers/evaluation.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/render_flags.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

// The workspace, the protocol and the one configuration.
void AddProtocolFlags(OptionManager* options, EvaluationOptions* o) {
  options->AddRequired("workspace_path", &o->workspace_path, "prepared dense workspace");
  options->AddRequired("output_path", &o->output_path, "folder for the reports");
  options->AddDefault("protocol", &o->protocol.protocol,
                      "auto (holdout when W/fvs/holdout.txt lists images, else "
                      "leave_one_out), holdout, leave_one_out, subsequence, indices");
  options->AddDefault("every", &o->protocol.every,
                      "leave_one_out: every n-th image (name order)");
  options->AddDefault("subsequence", &o->protocol.subsequence,
                      "subsequence: START:LENGTH, positions in name order, withheld");
  options->AddDefault("target_indices", &o->protocol.target_indices,
                      "indices: comma-separated positions (name order, from 0)");
  options->AddDefault("target_names", &o->protocol.target_names,
                      "indices: comma-separated image names");
  options->AddDefault(
      "method", &o->config.method,
      "ulr, nearest, fvs or a variant (fvs_fast, ...; needs --model_path)");
  options->AddDefault("model_path", &o->config.model_path, "network weights");
  options->AddDefault("num_sources", &o->config.num_sources,
                      "K sources per target; 0 = adaptive, up to --max_num_sources");
  options->AddDefault("scale", &o->config.scale,
                      "render at this fraction of the photo size (upsampled to score)");
}

// Sweeps, shards, LPIPS and what the reports show.
void AddSweepAndReportFlags(OptionManager* options, EvaluationOptions* o) {
  options->AddDefault("sweep", &o->sweep,
                      "render every configuration of the --sweep_* lists: Pareto table "
                      "and plot of quality against seconds per view");
  options->AddDefault("sweep_methods", &o->sweep_options.methods, "methods to sweep");
  options->AddDefault("sweep_num_sources", &o->sweep_options.num_sources,
                      "K values (auto: adaptive)");
  options->AddDefault("sweep_scales", &o->sweep_options.scales, "resolution scales");
  options->AddDefault("precision", &o->config.precision,
                      "network methods: fp32, bf16, or fp16 (CUDA only)");
  options->AddDefault("sweep_precisions", &o->sweep_options.precisions,
                      "precisions of the network methods: fp32, bf16 (CPU or CUDA), fp16 "
                      "(CUDA)");
  options->AddDefault("sweep_model_paths", &o->sweep_options.model_paths,
                      "weight files of network variants to sweep (comma-separated)");
  options->AddDefault("shard", &o->shard,
                      "i/n: evaluate only targets i, i+n, i+2n, ... (merge the shards "
                      "with view_synthesis_eval_merge)");
  options->AddDefault("lpips_path", &o->lpips_path,
                      "LPIPS weights, AlexNet or VGG16 (safetensors, see "
                      "doc/evaluation.md; default $FVS_LPIPS_PATH); without them LPIPS "
                      "is n/a");
  options->AddDefault("time", &o->time,
                      "time of the Pareto front and the plot: wall, or cpu (CPU seconds "
                      "of all threads, steadier on a shared machine); both are reported");
  options->AddDefault("scene_name", &o->scene_name,
                      "name in the reports (default: the workspace folder's name)");
  options->AddDefault("thumbnail_width", &o->thumbnail_width,
                      "contact sheet tile width (0: no contact sheet)");
  options->AddDefault("write_images", &o->write_images,
                      "also write every render to O/renders/<configuration>/");
  options->AddDefault(
      "overwrite", &o->overwrite,
      "evaluate every view again (default: the views a killed or earlier "
      "run with the same settings finished, kept in O/views/, are reused)");
}

int RunViewSynthesisEval(int argc, char** argv) {
  EvaluationOptions o;
  OptionManager options("view_synthesis_eval",
                        "Render held-out views of a prepared workspace and score them "
                        "against the photos (PSNR, SSIM, LPIPS) beside their run time.");
  AddProtocolFlags(&options, &o);
  AddSweepAndReportFlags(&options, &o);
  AddRenderEngineFlags(&options, &o.render);
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(o.output_path, "view_synthesis_eval", o.shard);
  const EvaluationResult result = RunEvaluation(o);
  PrintEvaluationSummary(o, result);
  RequireNoFailedViews(o, result);
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_eval",
                     "render held-out views, PSNR/SSIM/LPIPS beside seconds per view",
                     RunViewSynthesisEval);

}  // namespace fvs
