#include "fvs/train/scene_refine.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "colmap_ext/workspace.h"
#include "fvs/geometry/ply.h"
#include "fvs/scene/scene.h"
#include "fvs/train/data.h"
#include "fvs/train/pack.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/hash.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;
const char kSubject[] = "view_synthesis_refine";

struct RefineState {
  std::string base_hash;  // of the mesh refined (prepare's)
  double pack_scale = 0;
  double minutes_done = 0;  // budget of the last finished run (0: none)
  double seconds = 0;       // wall time of all runs, packing included
  int steps = 0;
  // Writing the result and the source depths, as the last run measured them (0: none).
  double finish_seconds = 0;
};

RefineState ReadState(const fs::path& file) {
  RefineState s;
  if (!fs::is_regular_file(file)) return s;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadFileToString(file.string()));
    s.base_hash = j.at("base_hash").get<std::string>();
    s.pack_scale = j.at("pack_scale").get<double>();
    s.minutes_done = j.at("minutes_done").get<double>();
    s.seconds = j.at("seconds").get<double>();
    s.steps = j.at("steps").get<int>();
    s.finish_seconds = j.value("finish_seconds", 0.0);  // absent before session 28
  } catch (const std::exception&) {
    return RefineState();  // unreadable: start afresh
  }
  return s;
}

void WriteState(const fs::path& file, const RefineState& s) {
  const nlohmann::json j = {{"base_hash", s.base_hash},
                            {"pack_scale", s.pack_scale},
                            {"minutes_done", s.minutes_done},
                            {"seconds", s.seconds},
                            {"steps", s.steps},
                            {"finish_seconds", s.finish_seconds}};
  WriteFileAtomic(file.string(), [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

TriangleMesh Shifted(TriangleMesh mesh, const Eigen::Vector3d& by) {
  for (Eigen::Vector3d& v : mesh.vertices) v += by;
  return mesh;
}

void WriteMesh(const fs::path& path, const TriangleMesh& world_mesh) {
  PlyWriteOptions write;
  write.double_precision = true;  // a scene far from the origin stays exact
  WritePlyMesh(path.string(), world_mesh, write);
}

// The offsets a saved mesh holds over the base (empty when it does not match it).
std::vector<Eigen::Vector3d> SavedOffsets(const fs::path& saved,
                                          const TriangleMesh& base) {
  if (!fs::is_regular_file(saved)) return {};
  const TriangleMesh mesh = ReadPlyMesh(saved.string());
  if (mesh.vertices.size() != base.vertices.size() || mesh.faces != base.faces) return {};
  std::vector<Eigen::Vector3d> offsets(base.vertices.size());
  for (size_t i = 0; i < offsets.size(); ++i) {
    offsets[i] = mesh.vertices[i] - base.vertices[i];
    if (!offsets[i].allFinite()) offsets[i].setZero();
  }
  return offsets;
}

void WriteCard(const fs::path& file, const SceneRefineOptions& o,
               const RefineState& state, const std::string& base_path,
               const MeshPhotoRefineResult& r) {
  const nlohmann::json j = {
      {"what",
       "proxy mesh refined by the photo-consistency of its leave-one-out renders"},
      {"base_mesh", base_path},
      {"minutes_budget", o.minutes},
      {"pack_scale", o.pack_scale},
      {"steps", state.steps},
      {"seconds", state.seconds},
      {"targets", r.num_targets},
      {"error_before_after", {r.initial_error, r.final_error}},
      {"median_edge", r.median_edge},
      {"move_median_max_edges", {r.median_move, r.max_move}},
      {"options",
       {{"num_sources", o.refine.num_sources},
        {"pixels_per_step", o.refine.pixels_per_step},
        {"step", o.refine.step},
        {"smoothness", o.refine.smoothness},
        {"max_move", o.refine.max_move},
        {"steps_per_raster", o.refine.steps_per_raster}}}};
  WriteFileAtomic(file.string(), [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

}  // namespace

void SceneRefineOptions::Check() const {
  Require(!workspace_path.empty(), kSubject, "--workspace_path is required");
  Require(minutes > 0 && std::isfinite(minutes), kSubject, "--minutes must be positive");
  Require(pack_scale > 0 && pack_scale <= 1, kSubject,
          "--Refine.pack_scale must be in (0, 1]");
  MeshPhotoRefineOptions r = refine;
  r.seconds = 1;
  r.Check();
}

SceneRefineSummary RunSceneRefine(const SceneRefineOptions& o) {
  o.Check();
  Timer timer;
  const colmap::DenseWorkspace ws(o.workspace_path);
  colmap::CheckDenseWorkspace(ws);
  const std::string base_path = ws.PreparedMeshPath();
  Require(fs::is_regular_file(base_path), base_path,
          "no mesh: run view_synthesis_prepare");
  // Read (and so checked) before anything is written into the workspace.
  const TriangleMesh world_base = ReadPlyMesh(base_path);
  const fs::path root = fs::path(ws.FvsDir()) / "refine";
  const fs::path result_path = ws.SceneRefinedMeshPath();
  fs::create_directories(root);
  const fs::path state_file = root / "state.json";
  RefineState state = ReadState(state_file);
  const std::string base_hash = HexHash(HashFile(base_path));
  // Another mesh, or the same one written again by a prepare after the result (which the
  // renderers then ignore, DenseWorkspace::ProxyMeshPath): what was refined is of no use.
  const bool stale =
      fs::is_regular_file(result_path) && ws.ProxyMeshPath() != result_path;
  if (state.base_hash != base_hash || stale) {
    fs::remove(result_path);
    fs::remove(root / "checkpoint.ply");
    state = RefineState();
    state.base_hash = base_hash;
  }
  SceneRefineSummary summary;
  summary.mesh_path = result_path.string();
  // Nothing (more) to do: the result as it stands.
  auto as_done = [&] {
    summary.already_done = true;
    summary.steps = state.steps;
    summary.seconds = state.seconds;
    return summary;
  };
  if (state.minutes_done >= o.minutes && fs::is_regular_file(result_path))
    return as_done();
  if (!fs::is_regular_file(root / "pack" / kPackedSceneFile) ||
      state.pack_scale != o.pack_scale) {
    if (!o.quiet)
      std::cerr << "[refine] packing the scene at scale " << o.pack_scale << "\n";
    SceneLoadOptions load;
    load.num_threads = o.refine.num_threads;
    PackOptions pack;
    pack.scale = o.pack_scale;
    pack.num_threads = o.refine.num_threads;
    PackScene(Scene::Load(o.workspace_path, load), pack, (root / "pack").string());
    state.pack_scale = o.pack_scale;
  }
  WriteState(state_file, state);
  const PackedScene scene = LoadPackedScene((root / "pack").string());
  const TriangleMesh base = Shifted(world_base, -scene.origin);
  std::vector<Eigen::Vector3d> offsets =
      SavedOffsets(root / "checkpoint.ply", world_base);
  if (offsets.empty()) offsets = SavedOffsets(result_path, world_base);

  // What is left of the budget, less what writing the result and the source depths of
  // every view will take: about half of what the setup took, or half as much again as
  // the last run's finish took (a continued run has next to no setup; its finish took
  // 44 s on a loaded machine where 2 s had been kept), at least 2 s, at most a fifth of
  // the budget.
  const double spent_before = state.seconds;
  const double reserve =
      std::min(0.2 * o.minutes * 60,
               std::max({2.0, 0.5 * timer.Seconds(), 1.5 * state.finish_seconds}));
  MeshPhotoRefineOptions refine = o.refine;
  refine.quiet = o.quiet;
  refine.seconds = o.minutes * 60 - spent_before - timer.Seconds() - reserve;
  if (refine.seconds <= 1) {
    Require(fs::is_regular_file(result_path), kSubject,
            "the budget of --minutes " + std::to_string(o.minutes) +
                " is spent before refining: give more minutes");
    return as_done();
  }
  refine.checkpoint = [&](const TriangleMesh& mesh, int steps) {
    WriteMesh(root / "checkpoint.ply", Shifted(mesh, scene.origin));
    RefineState now = state;  // what a killed run has spent
    now.seconds = spent_before + timer.Seconds();
    now.steps = state.steps + steps;
    WriteState(state_file, now);
  };
  summary.last = RefineMeshByPhotoConsistency(scene, base, refine, offsets);
  const double finish_start = timer.Seconds();
  WriteMesh(result_path, Shifted(summary.last.mesh, scene.origin));
  fs::remove(root / "checkpoint.ply");
  // The source depths of every view from the new mesh, so the first render does not
  // pay for them (Scene::Load renders what is stale into W/fvs/depth).
  SceneLoadOptions load;
  load.num_threads = o.refine.num_threads;
  Scene::Load(o.workspace_path, load);
  state.steps += summary.last.steps;
  state.seconds = spent_before + timer.Seconds();
  state.finish_seconds = timer.Seconds() - finish_start;
  state.minutes_done = o.minutes;
  WriteCard(root / "refine.json", o, state, base_path, summary.last);
  WriteState(state_file, state);
  summary.steps = state.steps;
  summary.seconds = state.seconds;
  return summary;
}

}  // namespace fvs
