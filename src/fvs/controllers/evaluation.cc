#include "fvs/controllers/evaluation.h"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "fvs/controllers/evaluation_report.h"
#include "fvs/controllers/render_settings.h"
#include "fvs/eval/lpips.h"
#include "fvs/eval/view_journal.h"
#include "fvs/render/fvs_method.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/hash.h"
#include "fvs/util/machine.h"
#include "fvs/util/shard.h"

namespace fvs {
namespace {

using eval::EvalConfig;
using eval::EvalRunOptions;
using eval::EvalTarget;
using eval::TargetSet;
using eval::ViewResult;

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

// The render options every configuration shares (checked).
EvalRunOptions BaseRunOptions(const EvaluationOptions& o) {
  EvalRunOptions run;
  run.render = o.render;
  run.render.scene_model_dir = WorkspaceFinetunedModelDir(o.workspace_path);
  run.render.Check();
  return run;
}

// The sweep's configurations, or the one of --method/--num_sources/--scale, whose method
// must be able to run (created once here, so that it fails before the scene loads).
std::vector<EvalConfig> PlanConfigs(const EvaluationOptions& o, const RenderOptions& base,
                                    std::vector<std::string>* notes) {
  if (o.sweep) {
    eval::SweepOptions sweep = o.sweep_options;
    if (!o.config.model_path.empty()) {
      sweep.model_paths += (sweep.model_paths.empty() ? "" : ",") + o.config.model_path;
    }
    eval::SweepPlan plan = eval::PlanSweep(sweep);
    for (const std::string& n : plan.notes) notes->push_back("sweep: " + n);
    return plan.configs;
  }
  RenderOptions render = base;
  render.num_sources = o.config.num_sources;
  render.model_path = o.config.model_path;
  render.precision = o.config.precision;
  render.Check();
  CreateMethod(o.config.method, render);  // throws for a method that cannot run
  return {o.config};
}

// LPIPS from --lpips_path, else the environment's default; without weights the column
// is n/a and a note says why.
void LoadLpipsInto(const EvaluationOptions& o, EvalRunOptions* run,
                   std::vector<std::string>* notes) {
  const std::string lpips_path = ResolveLpipsPath(o.lpips_path);
  std::string why_not, network;
  run->lpips = eval::LoadLpips(lpips_path, &why_not, &network);
  if (run->lpips) {
    notes->push_back("LPIPS v0.1 (" + network + ") from " + lpips_path);
  } else {
    notes->push_back(why_not);
    if (!lpips_path.empty()) std::fprintf(stderr, "WARNING: %s\n", why_not.c_str());
  }
}

std::string SceneName(const EvaluationOptions& o) {
  if (!o.scene_name.empty()) return o.scene_name;
  const std::string name =
      std::filesystem::path(o.workspace_path).lexically_normal().filename();
  return name.empty() ? o.workspace_path : name;
}

// The contact sheet shows the configuration of --method/--num_sources/--scale (the
// first of the sweep when that one is not part of it).
size_t SheetConfig(const EvaluationOptions& o, const std::vector<EvalConfig>& configs) {
  size_t sheet = 0;
  for (size_t i = 0; i < configs.size(); ++i) {
    if (configs[i].Label() == o.config.Label()) sheet = i;
  }
  return sheet;
}

// The hash of the file at `path`, or "" when there is none.
std::string FileHashOrEmpty(const std::string& path) {
  std::error_code ec;
  if (path.empty() || !std::filesystem::is_regular_file(path, ec)) return "";
  return HexHash(HashFile(path));
}

// What decides a view's result, for the journal of finished views
// (eval/view_journal.h): change any of it and every view is evaluated again. Threads
// and the shard do not change a view's result.
std::string JournalSettings(const EvaluationOptions& o,
                            const std::vector<EvalConfig>& configs,
                            const std::string& scene_model_dir) {
  nlohmann::json json;
  json["workspace_hash"] = WorkspaceContentHash(o.workspace_path);
  json["scene_name"] = SceneName(o);
  json["protocol"] = {o.protocol.protocol, o.protocol.every, o.protocol.subsequence,
                      o.protocol.target_indices, o.protocol.target_names};
  json["configurations"] = nlohmann::json::array();
  for (const EvalConfig& c : configs) {
    std::string weights = c.model_path;
    if (weights.empty() && TraitsOfMethod(c.method).needs_weights) {
      weights = DefaultModelPath(c.method, scene_model_dir);
    }
    json["configurations"].push_back({c.Label(), FileHashOrEmpty(weights)});
  }
  json["lpips_hash"] = FileHashOrEmpty(ResolveLpipsPath(o.lpips_path));
  const RenderOptions& r = o.render;
  json["render"] = {{"max_num_sources", r.max_num_sources},
                    {"selection_tolerance", r.selection_tolerance},
                    {"warp_tolerance", r.warp_tolerance},
                    {"fill_holes", r.fill_holes},
                    {"interpolation", r.interpolation},
                    {"ulr_num_blend", r.ulr_num_blend},
                    {"ulr_resolution_weight", r.ulr_resolution_weight},
                    {"device", r.device},
                    {"tile_size", r.tile_size},
                    {"tile_overlap", r.tile_overlap}};
  json["thumbnail_width"] = o.thumbnail_width;
  json["write_images"] = o.write_images;
  return json.dump(2) + "\n";
}

}  // namespace

void EvaluationOptions::Check() const {
  protocol.Check();
  Shard::Parse(shard);
  Require(config.num_sources >= 0, "--num_sources",
          "must be at least 1, or 0 (adaptive)");
  Require(render.max_num_sources >= 1, "--max_num_sources", "must be at least 1");
  Require(config.scale > 0 && config.scale <= 4, "--scale", "must be in (0, 4]");
  eval::ParseTimeMeasure(time);
  Require(thumbnail_width >= 0, "--thumbnail_width", "must not be negative");
  if (sweep) sweep_options.Check();
}

EvaluationResult RunEvaluation(const EvaluationOptions& o) {
  o.Check();
  const Shard shard = Shard::Parse(o.shard);
  // Everything that can fail without the scene fails before loading it.
  std::vector<std::string> notes;
  EvalRunOptions run = BaseRunOptions(o);
  const std::vector<EvalConfig> configs = PlanConfigs(o, run.render, &notes);
  LoadLpipsInto(o, &run, &notes);

  const Scene scene = Scene::Load(o.workspace_path, {true, o.render.num_threads});
  std::vector<std::string> names;
  for (const SceneView& v : scene.views()) names.push_back(v.name);
  const TargetSet set =
      eval::SelectTargets(names, eval::ReadHoldoutNames(o.workspace_path), o.protocol);
  EvaluationResult result;
  for (int i : shard.Items(static_cast<int>(set.targets.size()))) {
    result.targets.push_back(set.targets[i]);
  }
  std::error_code ec;
  std::filesystem::create_directories(o.output_path, ec);
  Require(!ec, o.output_path, "cannot create the output folder: " + ec.message());

  std::vector<std::pair<int, std::string>> bad_photos;
  eval::PreloadPhotos(scene, &bad_photos);
  for (const auto& [index, error] : bad_photos) {
    std::fprintf(stderr, "WARNING: %s (kept out of every target's sources)\n",
                 error.c_str());
    notes.push_back("photo kept out of the sources: " + error);
  }
  result.notes = ProtocolNotes(set, shard, result.targets.size());
  result.notes.insert(result.notes.end(), notes.begin(), notes.end());
  result.scene_name = SceneName(o);
  run.scene_name = result.scene_name;
  if (o.write_images) run.write_images_dir = o.output_path + "/renders";
  const eval::ViewJournal journal(o.output_path + "/views",
                                  JournalSettings(o, configs, run.render.scene_model_dir),
                                  o.overwrite);
  run.journal = &journal;

  const size_t sheet_config = SheetConfig(o, configs);
  ContactSheetViews sheet;
  for (size_t i = 0; i < configs.size(); ++i) {
    EvalRunOptions config_run = run;
    config_run.thumbnail_width = i == sheet_config ? o.thumbnail_width : 0;
    std::vector<ViewResult> rows = eval::EvaluateTargets(
        scene, set, result.targets, configs[i], config_run, bad_photos,
        i == sheet_config ? &sheet.thumbnails : nullptr);
    if (i == sheet_config) sheet.results = rows;
    result.results.insert(result.results.end(), rows.begin(), rows.end());
  }
  sheet.config = configs[sheet_config];
  result.machine = DescribeMachine();
  result.summary = eval::Summarize(result.results, eval::ParseTimeMeasure(o.time));
  WriteEvaluationReports(o, result, sheet, configs.size());
  return result;
}

}  // namespace fvs
