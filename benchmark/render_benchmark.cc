// Render benchmark: time per frame with its split (target depth, source selection, warp,
// blend) and the PSNR of the same frames against the exact ground truth, for `ulr` and
// `nearest` at 480x270 and 960x540 with K = 1..8, on a generated scene (synthetic room,
// exact mesh as the proxy), and for a network when given its weights (--model_path; the
// encode column is the mean per frame, sources cached across the frames of one K).
// Held-out views are rendered from the other views.
//   render_benchmark [--views N] [--frames F] [--max_k K] [--sizes 480x270,960x540]
//                    [--model_path weights.safetensors]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "fvs/eval/metrics.h"
#include "fvs/render/method.h"
#include "fvs/scene/scene.h"
#include "fvs/synthetic/render.h"
#include "fvs/synthetic/synthetic_scene.h"
#include "fvs/util/machine.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

int main(int argc, char** argv) {
  fvs::benchmark::CheckArgs(
      argc, argv,
      "usage: render_benchmark [--views N] [--frames F] [--max_k K] [--sizes "
      "480x270,960x540] [--model_path weights.safetensors] [--precision fp32|bf16|fp16]",
      {"--frames", "--max_k", "--model_path", "--precision", "--sizes", "--tile_overlap",
       "--tile_size", "--views"});
  int num_views = 16, num_frames = 3, max_k = 8;
  std::string model_path;
  std::string precision = "fp32";  // of the network: fp32, bf16 (CPU) or fp16 (CUDA)
  fvs::RenderOptions defaults;
  int tile_size = defaults.tile_size, tile_overlap = defaults.tile_overlap;
  std::vector<std::pair<int, int>> sizes = {{480, 270}, {960, 540}};
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--views") num_views = std::atoi(v.c_str());
    if (a == "--frames") num_frames = std::atoi(v.c_str());
    if (a == "--max_k") max_k = std::atoi(v.c_str());
    if (a == "--model_path") model_path = v;
    if (a == "--precision") precision = v;
    if (a == "--tile_size") tile_size = std::atoi(v.c_str());
    if (a == "--tile_overlap") tile_overlap = std::atoi(v.c_str());
    if (a == "--sizes") {
      sizes.clear();
      size_t p = 0;
      while (p < v.size()) {
        const size_t q = v.find(',', p);
        const std::string s =
            v.substr(p, q == std::string::npos ? std::string::npos : q - p);
        sizes.push_back({std::atoi(s.c_str()), std::atoi(s.c_str() + s.find('x') + 1)});
        p = q == std::string::npos ? v.size() : q + 1;
      }
    }
  }
  std::printf("machine: nproc %u, threads used %d, CPU %s\n",
              std::thread::hardware_concurrency(), fvs::DefaultNumThreads(),
              fvs::CpuModelName().c_str());
  std::printf(
      "scene: synthetic room, %d views, exact mesh as proxy; %d held-out frames\n",
      num_views, num_frames);
  try {
    for (const auto& [width, height] : sizes) {
      fvs::SyntheticSceneOptions options;
      options.num_views = num_views;
      options.width = width;
      options.height = height;
      options.supersampling = 1;
      fvs::Timer timer;
      const fvs::SyntheticScene synthetic = fvs::BuildSyntheticScene(options);
      std::vector<fvs::SceneView> views;
      std::vector<fvs::Image> photos(num_views);
      for (int i = 0; i < num_views; ++i) {
        views.push_back({synthetic.image_names[i], static_cast<uint32_t>(i + 1), 1,
                         synthetic.cameras[i]});
        fvs::RenderSyntheticView(synthetic, synthetic.cameras[i], &photos[i], nullptr,
                                 nullptr, 1);
      }
      fvs::Scene scene = fvs::Scene::FromWorld(views, synthetic.mesh);
      for (int i = 0; i < num_views; ++i) scene.SetSourceImage(i, photos[i]);
      std::printf("\n%dx%d: scene built in %.2f s (source depths %.2f s)\n", width,
                  height, timer.Seconds(), scene.load_seconds());
      std::printf("%-8s %2s %9s %9s %9s %9s %9s %9s %9s %9s\n", "method", "K", "psnr_dB",
                  "total_s", "depth_s", "select_s", "warp_s", "encode_s", "blend_s",
                  "coverage");
      std::vector<std::string> methods = {"nearest", "ulr"};
      if (!model_path.empty()) methods.push_back("fvs");
      for (const std::string& method : methods) {
        for (int k = 1; k <= max_k; ++k) {
          if (method == "nearest" && k > 1) break;  // uses the best source only
          fvs::RenderOptions render;
          render.num_sources = k;
          render.model_path = model_path;
          render.precision = precision;
          render.tile_size = tile_size;
          render.tile_overlap = tile_overlap;
          auto renderer = fvs::CreateMethod(method, render);
          fvs::RenderTimings sum;
          double psnr = 0, coverage = 0;
          for (int f = 0; f < num_frames; ++f) {
            const int held_out = (f + 1) * num_views / (num_frames + 1);
            fvs::TargetView target;
            target.name = views[held_out].name;
            target.camera = scene.view(held_out).camera;
            target.exclude_views = {held_out};
            const fvs::RenderResult r = renderer->Render(scene, target);
            // The evaluation protocol: 8-bit prediction, as a saved PNG.
            psnr +=
                fvs::eval::Psnr(fvs::eval::QuantizeTo8Bit(r.color), photos[held_out]) /
                num_frames;
            double covered = 0;
            for (float c : r.coverage.data) covered += c;
            coverage += covered / r.coverage.data.size() / num_frames;
            sum.depth_s += r.timings.depth_s / num_frames;
            sum.selection_s += r.timings.selection_s / num_frames;
            sum.warp_s += r.timings.warp_s / num_frames;
            sum.encode_s += r.timings.encode_s / num_frames;
            sum.blend_s += r.timings.blend_s / num_frames;
          }
          std::printf("%-8s %2d %9.2f %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %8.1f%%\n",
                      renderer->name().c_str(), k, psnr, sum.total(), sum.depth_s,
                      sum.selection_s, sum.warp_s, sum.encode_s, sum.blend_s,
                      100 * coverage);
          std::fflush(stdout);
        }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
}
