// The flicker metric (0 for a static consistent render, small for exact renders of a
// moving camera, larger with injected noise, occlusion-checked), source hysteresis (fewer
// source-set changes along a path), the temporal blend (less flicker), and extreme paths
// (outside the room, through a wall, at the sky, a repeated pose): finite output and
// flagged frames.
#include "fvs/path/flicker.h"

#include <gtest/gtest.h>

#include <random>

#include "fvs/path/camera_path.h"
#include "fvs/path/temporal.h"
#include "fvs/render/prepare.h"
#include "scene/scene_fixture.h"

namespace fvs {
namespace {

using testing::ArcCamera;
using testing::LookAtCamera;
using testing::MakeTestWorldMesh;
using testing::RenderGroundTruth;

Image TrueDepth(const TriangleMesh& mesh, const PinholeCamera& camera) {
  return Rasterize(mesh, camera, RasterizeOptions()).depth;
}

void AddNoise(Image* image, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, static_cast<float>(sigma));
  for (float& v : image->data) v = std::clamp(v + noise(rng), 0.f, 1.f);
}

TEST(FlickerTest, ZeroForStaticRenderPositiveForNoise) {
  const TriangleMesh mesh = MakeTestWorldMesh();
  const PinholeCamera cam = ArcCamera(0.1, 80, 60);
  const Image color = RenderGroundTruth(mesh, cam);
  const Image depth = TrueDepth(mesh, cam);
  const FlickerPair still = MeasureFlicker(color, depth, cam, color, depth, cam);
  EXPECT_GT(still.covisible_fraction, 0.99);
  EXPECT_LT(still.mean_abs, 1e-3);
  Image noisy = color;
  AddNoise(&noisy, 0.05, 1);
  const FlickerPair with_noise = MeasureFlicker(color, depth, cam, noisy, depth, cam);
  // Gaussian noise of 0.05: mean |noise| = 0.05 * sqrt(2 / pi) * 255 = 10.2 levels
  // (a little less where the clamp bites).
  EXPECT_GT(with_noise.mean_abs, 8.0);
  EXPECT_LT(with_noise.mean_abs, 11.0);
}

TEST(FlickerTest, MovingCameraExactRendersAreConsistentAndOcclusionChecked) {
  const TriangleMesh mesh = MakeTestWorldMesh(Eigen::Vector3d(5e3, -1e4, 2e3));
  const Eigen::Vector3d offset(5e3, -1e4, 2e3);
  const PinholeCamera a = ArcCamera(0.00, 96, 72, offset);
  const PinholeCamera b = ArcCamera(0.03, 96, 72, offset);
  const Image ca = RenderGroundTruth(mesh, a), cb = RenderGroundTruth(mesh, b);
  const Image da = TrueDepth(mesh, a), db = TrueDepth(mesh, b);
  const FlickerPair exact = MeasureFlicker(ca, da, a, cb, db, b);
  EXPECT_GT(exact.covisible_fraction, 0.9);
  // Bilinear resampling of smooth vertex colours only.
  EXPECT_LT(exact.mean_abs, 2.0) << exact.mean_abs;
  Image noisy = cb;
  AddNoise(&noisy, 0.05, 2);
  EXPECT_GT(MeasureFlicker(ca, da, a, noisy, db, b).mean_abs, exact.mean_abs + 5);
  // Occlusion: frame t sees only a wall in front of everything -> nothing co-visible.
  TriangleMesh wall = mesh;
  testing::AddQuadGrid(
      &wall, a.Center() + a.R.transpose() * Eigen::Vector3d(-5, -5, 0.2) - offset,
      a.R.transpose() * Eigen::Vector3d(10, 0, 0),
      a.R.transpose() * Eigen::Vector3d(0, 10, 0), 4, 4, offset);
  const Image occluded = TrueDepth(wall, a);
  const FlickerPair blocked = MeasureFlicker(ca, occluded, a, cb, db, b);
  EXPECT_LT(blocked.covisible_fraction, 0.01);
}

// A path across the arc of sources, rendered with ulr.
struct SequenceFigures {
  double flicker = 0;
  int source_changes = 0;
  int flagged = 0;
  bool finite = true;
};

SequenceFigures RenderSequence(const Scene& scene,
                               const std::vector<TargetCamera>& frames,
                               RenderOptions render, const TemporalOptions& temporal) {
  auto method = CreateMethod("ulr", render);
  TemporalSequence sequence(temporal);
  SequenceFigures figures;
  std::vector<FrameReportRow> rows;
  for (const TargetCamera& f : frames) {
    TargetView view;
    view.name = f.name;
    view.camera = scene.ToSceneCamera(f.camera);
    sequence.PrepareView(&view);
    RenderResult result = method->Render(scene, view);
    figures.finite = figures.finite && testing::AllFinite(result.color) &&
                     testing::AllFinite(result.depth);
    rows.push_back(sequence.Finish(view, &result));
    figures.source_changes += std::max(0, rows.back().source_changes);
    figures.flagged += rows.back().flagged;
  }
  figures.flicker = SummariseFrameReport(rows, temporal.coverage_threshold).mean_flicker;
  return figures;
}

TEST(FlickerTest, HysteresisAndTemporalBlendReduceFlicker) {
  // Photos with different exposures (as real ones): a change of source set shows.
  Scene scene = testing::MakeTestScene(9, 64, 48);
  for (int i = 0; i < scene.num_views(); ++i) {
    Image photo = scene.SourceImage(i);
    for (float& v : photo.data) v = std::clamp(v * (i % 2 ? 0.75f : 1.2f), 0.f, 1.f);
    scene.SetSourceImage(i, photo);
  }
  std::vector<CameraPathKeyframe> keys = {{"a", ArcCamera(-0.55, 64, 48)},
                                          {"b", ArcCamera(0.55, 64, 48)}};
  for (auto& k : keys) k.camera.fx = k.camera.fy;
  CameraPathOptions path;
  path.fps = 12;
  path.smooth = false;
  const auto frames = InterpolateCameraPath(keys, path);
  RenderOptions render;
  render.num_sources = 3;
  render.ulr_num_blend = 3;
  TemporalOptions temporal;
  const SequenceFigures plain = RenderSequence(scene, frames, render, temporal);
  render.source_hysteresis = 0.5;
  render.stable_source_order = true;
  const SequenceFigures stable = RenderSequence(scene, frames, render, temporal);
  temporal.temporal_blend = 0.5;
  const SequenceFigures blended = RenderSequence(scene, frames, render, temporal);
  std::printf(
      "flicker (levels) / source changes: plain %.3f / %d, hysteresis %.3f / %d, "
      "+ blend %.3f / %d\n",
      plain.flicker, plain.source_changes, stable.flicker, stable.source_changes,
      blended.flicker, blended.source_changes);
  EXPECT_TRUE(plain.finite && stable.finite && blended.finite);
  EXPECT_GT(plain.source_changes, 0);
  EXPECT_LT(stable.source_changes, plain.source_changes);
  EXPECT_GT(plain.flicker, 0);
  EXPECT_LT(stable.flicker, plain.flicker);
  EXPECT_LT(blended.flicker, stable.flicker);
  EXPECT_EQ(plain.flagged, 0);
}

TEST(FlickerTest, HysteresisKeepsPreferredSourcesWithinTheMargin) {
  std::vector<SourceScore> ranked = {{0, 100, 0}, {1, 90, 0}, {2, 80, 0}, {3, 70, 0}};
  // Source 3 preferred: 70 * 1.3 = 91 beats 90 and 80.
  auto chosen = ApplySourceHysteresis(ranked, {3}, 0.3, 2);
  ASSERT_EQ(chosen.size(), 2u);
  EXPECT_EQ(chosen[0].view_index, 0);
  EXPECT_EQ(chosen[1].view_index, 3);
  // Off: the plain top 2.
  chosen = ApplySourceHysteresis(ranked, {3}, 0.0, 2);
  EXPECT_EQ(chosen[1].view_index, 1);
}

TEST(FlickerTest, ExtremePathsStayFiniteAndAreFlagged) {
  const Scene scene = testing::MakeTestScene(6, 48, 36);
  const Eigen::Vector3d inside(3.0, 0.5, 1.6);
  std::vector<CameraPathKeyframe> keys = {
      {"inside", ArcCamera(0.0, 48, 36)},
      // Through the wall at x = 5 to outside, looking away from the room.
      {"outside",
       LookAtCamera(Eigen::Vector3d(8, 0.5, 1.6), Eigen::Vector3d(20, 0.5, 1.6), 48, 36)},
      // Inside the box object (through geometry).
      {"in_box",
       LookAtCamera(Eigen::Vector3d(0, 0, 0.6), Eigen::Vector3d(1, 0, 0.6), 48, 36)},
      // Straight up at the ceiling from close by, and the same pose repeated.
      {"up", LookAtCamera(inside, inside + Eigen::Vector3d(0.01, 0, 1), 48, 36)},
      {"up_again", LookAtCamera(inside, inside + Eigen::Vector3d(0.01, 0, 1), 48, 36)}};
  for (auto& k : keys) k.camera.fx = k.camera.fy;
  CameraPathOptions path;
  path.fps = 3;
  path.coverage_width = 32;
  const CameraPathResult r = ComputeCameraPath(keys, path, &scene);
  for (const auto& f : r.frames) ASSERT_TRUE(f.camera.IsValid()) << f.name;
  // A frame outside the room, looking out, sees no surface at all: the sky case.
  std::vector<TargetCamera> frames = r.frames;
  frames.push_back(
      {"sky",
       LookAtCamera(Eigen::Vector3d(8, 0.5, 1.6), Eigen::Vector3d(20, 0.5, 1.6), 48, 36),
       ""});
  RenderOptions render;
  TemporalOptions temporal;
  temporal.temporal_blend = 0.3;
  for (const std::string method : {"ulr", "nearest"}) {
    auto renderer = CreateMethod(method, render);
    TemporalSequence sequence(temporal);
    int flagged = 0;
    for (const TargetCamera& f : frames) {
      TargetView view;
      view.name = f.name;
      view.camera = scene.ToSceneCamera(f.camera);
      sequence.PrepareView(&view);
      RenderResult result = renderer->Render(scene, view);
      const FrameReportRow row = sequence.Finish(view, &result);
      ASSERT_TRUE(testing::AllFinite(result.color)) << method << " " << f.name;
      ASSERT_TRUE(testing::AllFinite(result.confidence)) << method << " " << f.name;
      EXPECT_TRUE(std::isfinite(row.coverage));
      EXPECT_TRUE(std::isfinite(row.flicker));
      flagged += row.flagged;
      if (f.name == "sky") {
        EXPECT_TRUE(row.flagged);
      }
    }
    EXPECT_GT(flagged, 1) << method;
  }
}

}  // namespace
}  // namespace fvs
