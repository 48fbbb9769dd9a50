#include "fvs/train/finetune.h"

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "fvs/net/lpips_weights.h"
#include "fvs/net/net.h"
#include "fvs/scene/scene.h"
#include "fvs/train/pack.h"
#include "fvs/train/trainer.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/hash.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;
const char kSubject[] = "view_synthesis_finetune";

struct FinetuneState {
  std::string init_hash;  // "" = the variant's initial weights
  std::string variant;
  double pack_scale = 0;
  double pack_seconds = 0;
  double minutes_done = 0;  // budget of the last finished run (0: none finished)
};

FinetuneState ReadState(const fs::path& file) {
  FinetuneState s;
  if (!fs::is_regular_file(file)) return s;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadFileToString(file.string()));
    s.init_hash = j.at("init_hash").get<std::string>();
    s.variant = j.at("variant").get<std::string>();
    s.pack_scale = j.at("pack_scale").get<double>();
    s.pack_seconds = j.at("pack_seconds").get<double>();
    s.minutes_done = j.value("minutes_done", 0.0);
  } catch (const std::exception&) {
    return FinetuneState();  // unreadable: start afresh
  }
  return s;
}

void WriteState(const fs::path& file, const FinetuneState& s) {
  const nlohmann::json j = {{"init_hash", s.init_hash},
                            {"variant", s.variant},
                            {"pack_scale", s.pack_scale},
                            {"pack_seconds", s.pack_seconds},
                            {"minutes_done", s.minutes_done}};
  WriteFileAtomic(file.string(), [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

// Packs the workspace unless a pack at this scale exists; returns the seconds it took
// (now or in the run that made it). *packed_now: whether this call packed.
double EnsurePack(const FinetuneOptions& o, const fs::path& pack_dir,
                  FinetuneState* state, bool* packed_now) {
  *packed_now = !(fs::is_regular_file(pack_dir / kPackedSceneFile) &&
                  state->pack_scale == o.pack_scale);
  if (!*packed_now) return state->pack_seconds;
  Timer timer;
  if (!o.quiet)
    std::cerr << "[finetune] packing the scene at scale " << o.pack_scale << "\n";
  SceneLoadOptions load;
  load.num_threads = o.num_threads;
  const Scene scene = Scene::Load(o.workspace_path, load);
  PackOptions pack;
  pack.scale = o.pack_scale;
  pack.num_threads = o.num_threads;
  PackScene(scene, pack, pack_dir.string());
  state->pack_scale = o.pack_scale;
  state->pack_seconds = timer.Seconds();
  return state->pack_seconds;
}

// L1 + SSIM + LPIPS when LPIPS weights are there (as the generic fvs_agg run), else
// L1 + SSIM.
std::string ChooseFinetuneLoss(const FinetuneOptions& o) {
  if (o.loss != "auto") return o.loss;
  const std::string lpips = ResolveLpipsPath(o.lpips_path);
  return !lpips.empty() && fs::is_regular_file(lpips) ? "l1+ssim+lpips" : "l1+ssim";
}

TrainOptions MakeTrainOptions(const FinetuneOptions& o, const fs::path& root) {
  TrainOptions t;
  t.scene_list = (root / "scenes.txt").string();
  t.output_path = (root / "run").string();
  t.init_weights = o.model_path;
  t.variant = o.variant;
  t.lpips_path = o.lpips_path;
  t.loss = ChooseFinetuneLoss(o);
  t.max_steps = 1 << 30;  // the time budget stops it
  t.num_sources = o.num_sources;
  t.crop = o.crop;
  t.batch_size = o.batch_size;
  t.learning_rate = o.learning_rate;
  t.checkpoint_minutes = 2;
  t.log_every = 25;
  t.val_every = 0;
  t.seed = o.seed;
  t.num_threads = o.num_threads;
  t.quiet = o.quiet;
  return t;
}

// run/model.* -> W/fvs/finetuned/<variant>.*, the card told what it is.
std::string Publish(const FinetuneOptions& o, const fs::path& run,
                    const FinetuneSummary& s, const std::string& variant) {
  const fs::path out = WorkspaceFinetunedModelDir(o.workspace_path);
  fs::create_directories(out);
  const std::string weights = (out / (variant + ".safetensors")).string();
  const std::string bytes = ReadFileToString((run / "model.safetensors").string());
  WriteFileAtomic(weights, [&](std::ostream& f) { f << bytes; });
  nlohmann::json card =
      nlohmann::json::parse(ReadFileToString((run / "model.json").string()));
  card["weights"] = variant + ".safetensors";
  card["finetune"] = {{"workspace", fs::absolute(o.workspace_path).string()},
                      {"init_weights", s.init_path.empty() ? "initial" : s.init_path},
                      {"minutes_budget", o.minutes},
                      {"pack_scale", o.pack_scale},
                      {"pack_seconds", s.pack_seconds},
                      {"train_seconds", s.train_seconds},
                      {"steps", s.steps}};
  WriteFileAtomic((out / (variant + ".json")).string(),
                  [&](std::ostream& f) { f << card.dump(2) << "\n"; });
  return weights;
}

}  // namespace

void FinetuneOptions::Check() const {
  Require(!workspace_path.empty(), kSubject, "--workspace_path is required");
  Require(minutes > 0, kSubject, "--minutes must be positive");
  Require(pack_scale > 0 && pack_scale <= 1, kSubject, "--pack_scale must be in (0, 1]");
  Require(num_sources >= 1, kSubject, "--num_sources must be at least 1");
  Require(crop >= 16, kSubject, "--crop must be at least 16");
  Require(batch_size >= 1, kSubject, "--batch_size must be at least 1");
  Require(learning_rate > 0, kSubject, "--learning_rate must be positive");
}

FinetuneSummary RunFinetune(const FinetuneOptions& o) {
  o.Check();
  Timer timer;
  Require(fs::is_directory(o.workspace_path), o.workspace_path,
          "no such workspace folder");
  // Starting weights that are missing or do not load fail here, before anything is
  // written into the workspace: the pack below would otherwise be left behind (the
  // trainer loads them again; a file of some megabytes, read twice).
  if (!o.model_path.empty()) LoadModel(o.model_path, nullptr);
  const fs::path root = fs::path(o.workspace_path) / "fvs" / "finetune";
  fs::create_directories(root);
  const fs::path state_file = root / "state.json";
  FinetuneState state = ReadState(state_file);
  FinetuneSummary summary;
  summary.init_path = o.model_path;
  const std::string init_hash =
      o.model_path.empty() ? "" : HexHash(HashFile(o.model_path));
  if (state.init_hash != init_hash || state.variant != o.variant) {
    // Other starting weights: the old run is of no use (the pack still is).
    fs::remove_all(root / "run");
    state.minutes_done = 0;
  }
  state.init_hash = init_hash;
  state.variant = o.variant;
  const fs::path published = fs::path(WorkspaceFinetunedModelDir(o.workspace_path)) /
                             (o.variant + ".safetensors");
  if (state.minutes_done >= o.minutes && fs::is_regular_file(published)) {
    if (!o.quiet)
      std::cerr << "[finetune] " << published.string() << " is fine-tuned for "
                << state.minutes_done << " minutes already; nothing to do\n";
    summary.model_path = published.string();
    return summary;
  }
  if (o.model_path.empty() && !o.quiet) {
    std::cerr << "[finetune] no generic " << o.variant
              << " weights: starting from the variant's initial weights\n";
  }
  bool packed_now = false;
  summary.pack_seconds = EnsurePack(o, root / "pack", &state, &packed_now);
  WriteState(state_file, state);
  WriteFileAtomic((root / "scenes.txt").string(), [](std::ostream& f) { f << "pack\n"; });

  Trainer trainer(MakeTrainOptions(o, root));
  // The budget less packing (whichever run packed) and this run's own setup is what the
  // training of all runs together may take: a rerun with a larger budget trains on.
  const double setup = timer.Seconds() - (packed_now ? summary.pack_seconds : 0.0);
  trainer.SetMaxTrainSeconds(
      std::max(1e-3, o.minutes * 60 - summary.pack_seconds - setup));
  const TrainSummary trained = trainer.Run();
  summary.steps = trained.steps_done;
  summary.train_seconds = trainer.train_seconds();
  summary.interrupted = trained.interrupted;
  if (trained.interrupted) return summary;
  summary.model_path = Publish(o, root / "run", summary, trainer.config().variant);
  state.minutes_done = o.minutes;
  WriteState(state_file, state);
  return summary;
}

}  // namespace fvs
