// colmap view_synthesis_eval --workspace_path W --output_path O
//   protocol: --protocol auto|holdout|leave_one_out|subsequence|indices (--every N,
//             --subsequence START:LENGTH, --target_indices 0,5 / --target_names a.png)
//   one configuration: --method, --model_path, --num_sources K, --scale s
//   or --sweep 1: methods x K x scales x precisions (--sweep_* lists)
//   --shard i/n: only every n-th target (merge with view_synthesis_eval_merge)
//   --lpips_path: LPIPS weights (safetensors; default $FVS_LPIPS_PATH); without them
//                 LPIPS is "n/a"
// Renders the protocol's targets at the photos' size, scores them against the photos and
// writes O/results.csv, O/summary.csv, O/results.md, O/contact_sheet.png and, for more
// than one configuration, O/error_vs_time.png. Bad views are reported in their rows and
// the others still evaluated; the exit status is 1 when any view failed. A held-out image
// SfM did not register is listed as skipped (status "skipped", the reason in "error"),
// which is not a failure.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "colmap_ext/image_io.h"
#include "fvs/eval/contact_sheet.h"
#include "fvs/eval/evaluate.h"
#include "fvs/eval/lpips.h"
#include "fvs/eval/plot.h"
#include "fvs/eval/protocol.h"
#include "fvs/eval/report.h"
#include "fvs/eval/sweep.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/option_manager.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/progress.h"
#include "fvs/util/shard.h"

namespace fvs {
namespace {

using namespace eval;  // NOLINT: the command is a thin layer over fvs::eval

struct EvalCommandOptions {
  std::string workspace_path;
  std::string output_path;
  ProtocolOptions protocol;
  EvalConfig config;
  bool sweep = false;
  SweepOptions sweep_options;
  std::string shard;
  std::string lpips_path;
  std::string time = "wall";
  std::string scene_name;
  int thumbnail_width = 320;
  bool write_images = false;
  int num_threads = 0;
  int max_num_sources = RenderOptions().max_num_sources;
  bool fill_holes = true;
  std::string device = "auto";

  void Check() const {
    protocol.Check();
    Shard::Parse(shard);
    Require(config.num_sources >= 0, "--num_sources",
            "must be at least 1, or 0 (adaptive)");
    Require(max_num_sources >= 1, "--max_num_sources", "must be at least 1");
    Require(config.scale > 0 && config.scale <= 4, "--scale", "must be in (0, 4]");
    ParseTimeMeasure(time);
    Require(thumbnail_width >= 0, "--thumbnail_width", "must not be negative");
    if (sweep) sweep_options.Check();
  }
};

std::vector<std::string> ProtocolNotes(const TargetSet& set, const Shard& shard,
                                       size_t num_targets) {
  std::vector<std::string> notes;
  std::string line = "protocol: " + set.protocol + ", " + std::to_string(num_targets) +
                     " target view(s)";
  if (!shard.IsAll()) {
    line +=
        " (shard " + shard.ToString() + " of " + std::to_string(set.targets.size()) + ")";
  }
  notes.push_back(line);
  if (set.protocol == "leave_one_out" || set.protocol == "subsequence" ||
      set.protocol == "indices") {
    notes.push_back(
        "targets not listed in W/fvs/holdout.txt were part of the dense geometry (the "
        "mesh saw them); they are only kept out of the sources. Column 'held out of the "
        "mesh' says which targets are true holdouts.");
  }
  notes.push_back(
      "predictions quantised to 8 bits; renders at scale < 1 are upsampled "
      "(bilinear) to the photo's size before PSNR / SSIM / LPIPS; s = wall "
      "time of the render per view, CPU s = CPU time of all threads over the "
      "same span; photos preloaded");
  return notes;
}

int RunViewSynthesisEval(int argc, char** argv) {
  EvalCommandOptions o;
  OptionManager options("view_synthesis_eval",
                        "Render held-out views of a prepared workspace and score them "
                        "against the photos (PSNR, SSIM, LPIPS) beside their run time.");
  options.AddRequired("workspace_path", &o.workspace_path, "prepared dense workspace");
  options.AddRequired("output_path", &o.output_path, "folder for the reports");
  options.AddDefault("protocol", &o.protocol.protocol,
                     "auto (holdout when W/fvs/holdout.txt lists images, else "
                     "leave_one_out), holdout, leave_one_out, subsequence, indices");
  options.AddDefault("every", &o.protocol.every,
                     "leave_one_out: every n-th image (name order)");
  options.AddDefault("subsequence", &o.protocol.subsequence,
                     "subsequence: START:LENGTH, positions in name order, withheld");
  options.AddDefault("target_indices", &o.protocol.target_indices,
                     "indices: comma-separated positions (name order, from 0)");
  options.AddDefault("target_names", &o.protocol.target_names,
                     "indices: comma-separated image names");
  options.AddDefault(
      "method", &o.config.method,
      "ulr, nearest, fvs or a variant (fvs_fast, ...; needs --model_path)");
  options.AddDefault("model_path", &o.config.model_path, "network weights");
  options.AddDefault("num_sources", &o.config.num_sources,
                     "K sources per target; 0 = adaptive, up to --max_num_sources");
  options.AddDefault("max_num_sources", &o.max_num_sources,
                     "the most sources an adaptive K (0, auto) takes");
  options.AddDefault("scale", &o.config.scale,
                     "render at this fraction of the photo size (upsampled to score)");
  options.AddDefault("sweep", &o.sweep,
                     "render every configuration of the --sweep_* lists: Pareto table "
                     "and plot of quality against seconds per view");
  options.AddDefault("sweep_methods", &o.sweep_options.methods, "methods to sweep");
  options.AddDefault("sweep_num_sources", &o.sweep_options.num_sources,
                     "K values (auto: adaptive)");
  options.AddDefault("sweep_scales", &o.sweep_options.scales, "resolution scales");
  options.AddDefault("precision", &o.config.precision,
                     "network methods: fp32, bf16, or fp16 (CUDA only)");
  options.AddDefault("device", &o.device, "network methods: auto, cpu or cuda");
  options.AddDefault("sweep_precisions", &o.sweep_options.precisions,
                     "precisions of the network methods: fp32, bf16 (CPU or CUDA), fp16 "
                     "(CUDA)");
  options.AddDefault("sweep_model_paths", &o.sweep_options.model_paths,
                     "weight files of network variants to sweep (comma-separated)");
  options.AddDefault("shard", &o.shard,
                     "i/n: evaluate only targets i, i+n, i+2n, ... (merge the shards "
                     "with view_synthesis_eval_merge)");
  options.AddDefault("lpips_path", &o.lpips_path,
                     "LPIPS weights, AlexNet or VGG16 (safetensors, see "
                     "doc/evaluation.md; default $FVS_LPIPS_PATH); without them LPIPS "
                     "is n/a");
  options.AddDefault("time", &o.time,
                     "time of the Pareto front and the plot: wall, or cpu (CPU seconds "
                     "of all threads, steadier on a shared machine); both are reported");
  options.AddDefault("scene_name", &o.scene_name,
                     "name in the reports (default: the workspace folder's name)");
  options.AddDefault("thumbnail_width", &o.thumbnail_width,
                     "contact sheet tile width (0: no contact sheet)");
  options.AddDefault("write_images", &o.write_images,
                     "also write every render to O/renders/<configuration>/");
  options.AddDefault("fill_holes", &o.fill_holes,
                     "fill pixels no source sees from around them (0: black; the "
                     "covered-pixel scores are the same either way)");
  options.AddDefault("num_threads", &o.num_threads, "threads (0: all cores)");
  if (!options.Parse(argc, argv)) return 0;
  o.Check();
  const Shard shard = Shard::Parse(o.shard);

  // Everything that can fail without the scene fails before loading it.
  std::vector<EvalConfig> configs;
  std::vector<std::string> notes;
  EvalRunOptions run;
  run.render.num_threads = o.num_threads;
  run.render.max_num_sources = o.max_num_sources;
  run.render.fill_holes = o.fill_holes;
  run.render.device = o.device;
  run.render.scene_model_dir = WorkspaceFinetunedModelDir(o.workspace_path);
  run.render.Check();
  if (o.sweep) {
    SweepOptions sweep = o.sweep_options;
    if (!o.config.model_path.empty()) {
      sweep.model_paths += (sweep.model_paths.empty() ? "" : ",") + o.config.model_path;
    }
    SweepPlan plan = PlanSweep(sweep);
    configs = plan.configs;
    for (const std::string& n : plan.notes) notes.push_back("sweep: " + n);
  } else {
    RenderOptions render = run.render;
    render.num_sources = o.config.num_sources;
    render.model_path = o.config.model_path;
    render.precision = o.config.precision;
    render.Check();
    CreateMethod(o.config.method, render);  // throws for a method that cannot run
    configs.push_back(o.config);
  }
  // The flag wins over the environment's default.
  const std::string lpips_path = ResolveLpipsPath(o.lpips_path);
  std::string lpips_why_not, lpips_network;
  run.lpips = LoadLpips(lpips_path, &lpips_why_not, &lpips_network);
  if (run.lpips) {
    notes.push_back("LPIPS v0.1 (" + lpips_network + ") from " + lpips_path);
  } else {
    notes.push_back(lpips_why_not);
    if (!lpips_path.empty()) std::fprintf(stderr, "WARNING: %s\n", lpips_why_not.c_str());
  }

  Scene scene = Scene::Load(o.workspace_path, {true, o.num_threads});
  std::vector<std::string> names;
  for (const SceneView& v : scene.views()) names.push_back(v.name);
  const TargetSet set =
      SelectTargets(names, ReadHoldoutNames(o.workspace_path), o.protocol);
  std::vector<EvalTarget> targets;
  for (int i : shard.Items(static_cast<int>(set.targets.size()))) {
    targets.push_back(set.targets[i]);
  }
  std::error_code ec;
  std::filesystem::create_directories(o.output_path, ec);
  Require(!ec, o.output_path, "cannot create the output folder: " + ec.message());

  std::vector<std::pair<int, std::string>> bad_photos;
  PreloadPhotos(scene, &bad_photos);
  for (const auto& [index, error] : bad_photos) {
    std::fprintf(stderr, "WARNING: %s (kept out of every target's sources)\n",
                 error.c_str());
    notes.push_back("photo kept out of the sources: " + error);
  }
  std::vector<std::string> all_notes = ProtocolNotes(set, shard, targets.size());
  all_notes.insert(all_notes.end(), notes.begin(), notes.end());

  run.scene_name = o.scene_name;
  if (run.scene_name.empty()) {
    run.scene_name =
        std::filesystem::path(o.workspace_path).lexically_normal().filename();
  }
  if (run.scene_name.empty()) run.scene_name = o.workspace_path;
  if (o.write_images) run.write_images_dir = o.output_path + "/renders";
  // The contact sheet shows the configuration of --method/--num_sources/--scale (the
  // first of the sweep when that one is not part of it).
  size_t sheet_config = 0;
  for (size_t i = 0; i < configs.size(); ++i) {
    if (configs[i].Label() == o.config.Label()) sheet_config = i;
  }

  std::vector<ViewResult> results;
  std::vector<ViewResult> sheet_results;
  std::vector<ViewThumbnails> thumbnails;
  for (size_t i = 0; i < configs.size(); ++i) {
    EvalRunOptions config_run = run;
    config_run.thumbnail_width = i == sheet_config ? o.thumbnail_width : 0;
    std::vector<ViewResult> rows =
        EvaluateTargets(scene, set, targets, configs[i], config_run, bad_photos,
                        i == sheet_config ? &thumbnails : nullptr);
    if (i == sheet_config) sheet_results = rows;
    results.insert(results.end(), rows.begin(), rows.end());
  }

  const TimeMeasure time = ParseTimeMeasure(o.time);
  const std::vector<ConfigSummary> summary = Summarize(results, time);
  ReportContext context;
  context.title = "view_synthesis_eval: " + run.scene_name;
  context.machine = DescribeMachine();
  context.workspace = o.workspace_path;
  context.notes = all_notes;
  WriteResultsCsv(o.output_path + "/results.csv", results);
  WriteSummaryCsv(o.output_path + "/summary.csv", summary);
  WriteMarkdownReport(o.output_path + "/results.md", context, results, summary);
  WriteFileAtomic(o.output_path + "/machine.txt",
                  [&](std::ostream& out) { out << context.machine << "\n"; });
  if (o.thumbnail_width > 0) {
    colmap::WriteImage(
        o.output_path + "/contact_sheet.png",
        MakeContactSheet(run.scene_name + ": " + configs[sheet_config].Label() +
                             (shard.IsAll() ? "" : ", shard " + shard.ToString()),
                         sheet_results, thumbnails));
  }
  if (configs.size() > 1) {
    PlotOptions plot;
    plot.title = "Quality against run time: " + run.scene_name;
    plot.footer = context.machine;
    plot.time = time;
    try {
      colmap::WriteImage(o.output_path + "/error_vs_time.png",
                         PlotErrorAgainstTime(summary, plot));
    } catch (const Error& e) {
      std::fprintf(stderr, "WARNING: no plot: %s\n", e.what());
    }
  }

  std::printf("%s\n", context.machine.c_str());
  for (const std::string& n : all_notes) std::printf("%s\n", n.c_str());
  std::printf("%-26s %5s %6s %8s %8s %8s %9s %9s %9s %7s %6s\n", "configuration", "views",
              "failed", "PSNR", "SSIM", "LPIPS", "PSNR_cov", "s/view", "CPU_s", "K used",
              "Pareto");
  for (const ConfigSummary& s : summary) {
    std::printf("%-26s %5d %6d %8s %8s %8s %9s %9s %9s %7s %6s\n",
                s.config.Label().c_str(), s.views_ok, s.views_failed,
                FormatNumber(s.psnr, 2).c_str(), FormatNumber(s.ssim, 4).c_str(),
                FormatNumber(s.lpips, 4).c_str(), FormatNumber(s.psnr_covered, 2).c_str(),
                FormatNumber(s.seconds, 3).c_str(),
                FormatNumber(s.cpu_seconds, 3).c_str(),
                FormatNumber(s.sources_used, 1).c_str(), s.pareto ? "yes" : "");
  }
  std::printf("wrote %s/results.csv, summary.csv, results.md\n", o.output_path.c_str());

  for (const EvalTarget& t : targets) {
    if (t.skipped) std::printf("skipped %s: %s\n", t.name.c_str(), t.error.c_str());
  }
  int failed = 0;
  const ViewResult* first_failure = nullptr;
  for (const ViewResult& r : results) {
    if (r.failed()) {
      ++failed;
      if (!first_failure) first_failure = &r;
    }
  }
  if (failed > 0) {
    throw Error(o.output_path + "/results.csv",
                std::to_string(failed) + " of " + std::to_string(results.size()) +
                    " view evaluations failed (first: " + first_failure->target + ": " +
                    first_failure->error + "); the others are reported");
  }
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_eval",
                     "render held-out views, PSNR/SSIM/LPIPS beside seconds per view",
                     RunViewSynthesisEval);

}  // namespace fvs
