#include "fvs/eval/stability.h"

#include <Eigen/Geometry>
#include <cmath>

#include "fvs/geometry/look_at.h"
#include "fvs/geometry/quad_grid.h"
#include "fvs/geometry/rasterizer.h"
#include "fvs/scene/scene.h"
#include "fvs/util/progress.h"

namespace fvs::eval {
namespace {

// Floor and four walls of a roofless room (x in [-5, 5], y in [-4, 4], z in [0, 3]) with
// a box in the middle; optionally a sky plane 1e30 above.
TriangleMesh MakeWorld(bool far_backdrop) {
  TriangleMesh mesh;
  const Eigen::Vector3d ex(10, 0, 0), ey(0, 8, 0), ez(0, 0, 3);
  AddColouredQuadGrid(&mesh, {-5, -4, 0}, ex, ey, 40, 32);
  AddColouredQuadGrid(&mesh, {-5, -4, 0}, ex, ez, 40, 12);
  AddColouredQuadGrid(&mesh, {-5, 4, 0}, ex, ez, 40, 12);
  AddColouredQuadGrid(&mesh, {-5, -4, 0}, ey, ez, 32, 12);
  AddColouredQuadGrid(&mesh, {5, -4, 0}, ey, ez, 32, 12);
  const Eigen::Vector3d bx(1.4, 0, 0), by(0, 1.0, 0), bz(0, 0, 1.2);
  const Eigen::Vector3d lo(-0.7, -0.5, 0);
  AddColouredQuadGrid(&mesh, lo, bx, by, 6, 4);
  AddColouredQuadGrid(&mesh, lo + bz, bx, by, 6, 4);
  AddColouredQuadGrid(&mesh, lo, bx, bz, 6, 5);
  AddColouredQuadGrid(&mesh, lo + by, bx, bz, 6, 5);
  AddColouredQuadGrid(&mesh, lo, by, bz, 4, 5);
  AddColouredQuadGrid(&mesh, lo + bx, by, bz, 4, 5);
  if (far_backdrop) {
    AddColouredQuadGrid(&mesh, {-1e31, -1e31, 1e30}, {2e31, 0, 0}, {0, 2e31, 0}, 4, 4);
  }
  return mesh;
}

PinholeCamera LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& at, int width,
                     int height) {
  return LookAtCamera(eye, at, width, height, 0.8 * width);
}

PinholeCamera ArcCamera(double angle, int width, int height) {
  return LookAt({3.2 * std::cos(angle), 2.6 * std::sin(angle), 1.6}, {0, 0, 0.7}, width,
                height);
}

struct Case {
  std::string name;
  std::vector<PinholeCamera> sources;
  PinholeCamera target;
  int k = 5;
  bool far_backdrop = false;
};

std::vector<Case> MakeCases(int w, int h) {
  std::vector<PinholeCamera> arc;
  for (int i = 0; i < 6; ++i) arc.push_back(ArcCamera(-0.6 + 1.2 * i / 5, w, h));
  const PinholeCamera between = ArcCamera(-0.6 + 1.2 * 2.5 / 5, w, h);
  std::vector<Case> cases;
  cases.push_back({"reference", arc, between});
  cases.push_back({"depth_0", arc, LookAt({0, 0, 1.6}, {3, 0, 40}, w, h)});
  cases.push_back({"depth_1e30", arc, LookAt({0, 0, 1.6}, {3, 0, 40}, w, h), 5, true});
  // Standing above the box, looking past the sources at the wall behind them.
  cases.push_back({"behind_sources", arc, LookAt({0, 0, 1.6}, {5, 0, 1.4}, w, h)});
  // A source at the target's centre turned 90 degrees: the target's central column lies
  // in its image plane (camera-frame z = 0).
  Case edge{"edge_on", arc, between, 7};
  PinholeCamera side = between;
  // Turned about its own y axis: camera-frame (x, y, z) -> (z, y, -x).
  side.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix() *
           between.R;
  side.t = -side.R * between.Center();
  edge.sources.push_back(side);
  cases.push_back(edge);
  cases.push_back({"single_source", {arc[2]}, between});
  cases.push_back({"k_too_large", arc, between, 64});
  return cases;
}

Scene BuildScene(const Case& c, const TriangleMesh& world_mesh,
                 const Eigen::Vector3d& offset, int num_threads) {
  TriangleMesh mesh = world_mesh;
  for (Eigen::Vector3d& v : mesh.vertices) v += offset;
  std::vector<SceneView> views;
  for (size_t i = 0; i < c.sources.size(); ++i) {
    SceneView v;
    v.name = "source_" + std::to_string(i) + ".png";
    v.camera = c.sources[i];
    v.camera.t -= v.camera.R * offset;  // centre moves by offset
    views.push_back(v);
  }
  Scene scene = Scene::FromWorld(views, mesh, num_threads);
  RasterizeOptions raster;
  raster.compute_color = true;
  raster.num_threads = num_threads;
  for (size_t i = 0; i < views.size(); ++i) {
    scene.SetSourceImage(static_cast<int>(i),
                         Rasterize(mesh, views[i].camera, raster).color);
  }
  return scene;
}

void CountNonFinite(const Image& image, long* nan_count, long* inf_count) {
  for (float v : image.data) {
    if (std::isnan(v)) ++*nan_count;
    if (std::isinf(v)) ++*inf_count;
  }
}

}  // namespace

std::vector<std::string> StabilityCaseNames() {
  std::vector<std::string> names;
  for (const Case& c : MakeCases(8, 6)) names.push_back(c.name);
  return names;
}

std::vector<StabilityResult> RunStabilitySuite(const StabilityOptions& options) {
  const std::vector<Case> cases = MakeCases(options.width, options.height);
  const TriangleMesh world = MakeWorld(false), world_backdrop = MakeWorld(true);
  // 10 km along a horizontal diagonal (and a little up), so that all axes change.
  const Eigen::Vector3d far = options.far_offset_m * Eigen::Vector3d(0.8, -0.6, 0.0) +
                              Eigen::Vector3d(0, 0, 0.01 * options.far_offset_m);
  std::vector<StabilityResult> results;
  Progress progress("stability suite", static_cast<int64_t>(cases.size()));
  for (const Case& c : cases) {
    const TriangleMesh& mesh = c.far_backdrop ? world_backdrop : world;
    Scene near_scene = BuildScene(c, mesh, Eigen::Vector3d::Zero(), options.num_threads);
    Scene far_scene = BuildScene(c, mesh, far, options.num_threads);
    PinholeCamera far_target = c.target;
    far_target.t -= far_target.R * far;
    for (const std::string& method_name : options.methods) {
      StabilityResult r;
      r.case_name = c.name;
      r.method = method_name;
      try {
        RenderOptions render;
        render.num_sources = c.k;
        render.model_path = options.model_path;
        render.precision = options.precision;
        render.tile_size = options.tile_size;
        render.num_threads = options.num_threads;
        render.Check();
        Timer timer;
        // A fresh method per placement: nothing cached from one scene is reused.
        TargetView near_view, far_view;
        near_view.name = far_view.name = "target";
        near_view.camera = near_scene.ToSceneCamera(c.target);
        far_view.camera = far_scene.ToSceneCamera(far_target);
        const RenderResult a =
            CreateMethod(method_name, render)->Render(near_scene, near_view);
        const RenderResult b =
            CreateMethod(method_name, render)->Render(far_scene, far_view);
        r.seconds = timer.Seconds();
        for (const RenderResult* x : {&a, &b}) {
          CountNonFinite(x->color, &r.nan_count, &r.inf_count);
          CountNonFinite(x->confidence, &r.nan_count, &r.inf_count);
          CountNonFinite(x->depth, &r.nan_count, &r.inf_count);
        }
        double covered = 0;
        for (float v : a.coverage.data) covered += v > 0 ? 1 : 0;
        r.covered = covered / std::max<size_t>(1, a.coverage.data.size());
        for (size_t p = 0; p + 2 < a.color.data.size(); p += 3) {
          double pixel_max = 0;
          for (int ch = 0; ch < 3; ++ch) {
            const double d =
                std::abs(double(a.color.data[p + ch]) - b.color.data[p + ch]);
            pixel_max = std::isfinite(d) ? std::max(pixel_max, d) : 1e30;
          }
          r.max_deviation = std::max(r.max_deviation, pixel_max);
          if (pixel_max > 1.0 / 255) ++r.pixels_deviating;
        }
      } catch (const std::exception& e) {
        r.error = e.what();
      }
      results.push_back(r);
    }
    progress.Advance();
  }
  progress.Finish();
  return results;
}

}  // namespace fvs::eval
