#include "fvs/train/render_benchmark.h"

#include <torch/torch.h>
#include <torch/version.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <thread>

#include "fvs/net/net.h"
#include "fvs/net/precision.h"
#include "fvs/train/data.h"
#include "fvs/train/packed_render.h"
#include "fvs/train/trainer.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

struct Row {
  int width = 0, height = 0, k = 0;
  std::string precision;
  int views = 0;
  double warp_s = 0, cpu_warp_s = 0, network_s = 0, rest_s = 0, psnr = 0, ulr_psnr = 0;
  double total() const { return warp_s + network_s + rest_s; }
};

void WriteCsv(const std::string& path, const std::vector<Row>& rows) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << "width,height,k,precision,views,warp_s,cpu_warp_s,network_s,rest_s,total_s,"
           "psnr,ulr_psnr\n";
    char line[256];
    for (const Row& r : rows) {
      std::snprintf(line, sizeof(line),
                    "%d,%d,%d,%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f\n", r.width,
                    r.height, r.k, r.precision.c_str(), r.views, r.warp_s, r.cpu_warp_s,
                    r.network_s, r.rest_s, r.total(), r.psnr, r.ulr_psnr);
      out << line;
    }
  });
}

}  // namespace

TrainSummary RunRenderBenchmark(const TrainOptions& options) {
  options.Check();
  Timer clock;
  ConfigureTrainingThreads(options);
  const BenchmarkGrid grid = ParseBenchmarkGrid(options);
  const torch::Device device = TrainingDevice(options);
  // A fresh network per precision (casting one back and forth would round its weights).
  ModelConfig config;
  auto make_net = [&] {
    FvsNet net = InitialNetwork(options, &config);
    net->eval();
    return net;
  };
  make_net();  // the config, and a bad weights file fails before the scenes load
  std::vector<PackedScene> scenes;
  for (const std::string& folder : ReadSceneList(options.val_scene_list)) {
    scenes.push_back(LoadPackedScene(folder));
  }
  SampleWarpOptions warp = SampleWarpOptionsFor(config, options.occlusion_tolerance);
  warp.ulr_log_weights = true;  // the baseline's weights, and the prior's

  std::printf(
      "render benchmark: %s (%s weights), %s, LibTorch %d.%d.%d, %d threads, "
      "%u cores, %s\n",
      config.variant.c_str(),
      options.init_weights.empty() ? "fresh, untrained" : options.init_weights.c_str(),
      device.is_cuda() ? "CUDA" : "CPU", TORCH_VERSION_MAJOR, TORCH_VERSION_MINOR,
      TORCH_VERSION_PATCH, torch::get_num_threads(), std::thread::hardware_concurrency(),
      CpuModelName().c_str());
  std::printf(
      "scenes: %zu validation scene(s), %d view(s) each per cell, resized from "
      "the packs; time bound %.0f s\n",
      scenes.size(), options.bench_views, options.bench_seconds);
  std::printf("%9s %2s %5s %5s %9s %9s %9s %9s %9s %8s %8s\n", "size", "K", "prec",
              "views", "warp_s", "(cpu)", "network_s", "rest_s", "total_s", "psnr",
              "ulr");
  std::fflush(stdout);

  std::filesystem::create_directories(options.output_path);
  const std::string csv = options.output_path + "/render_benchmark.csv";
  std::vector<Row> rows;
  std::vector<std::string> skipped;
  c10::InferenceMode inference;
  std::map<std::string, FvsNet> nets;  // by precision, cast once
  // Seconds per source and pixel of the last cell of each precision (any size): the
  // prediction that keeps the grid within its bound.
  std::map<std::string, double> rate;
  for (const std::string& p : grid.precisions) {
    if (p == "fp16" && !device.is_cuda()) {
      skipped.push_back("fp16 (CPU: LibTorch's CPU convolutions have no fp16)");
      continue;
    }
    FvsNet net = make_net();
    net->to(device, PrecisionDtype(p));
    // Channels-last, as the renderer (FvsMethod).
    for (auto& t : net->parameters()) {
      if (t.dim() == 4) t.set_data(t.contiguous(torch::MemoryFormat::ChannelsLast));
    }
    nets.emplace(p, net);
  }
  for (size_t si = 0; si < grid.sizes.size(); ++si) {
    const auto [width, height] = grid.sizes[si];
    const double share = (options.bench_seconds - clock.Seconds()) /
                         static_cast<double>(grid.sizes.size() - si);
    Timer size_clock;
    std::vector<PackedScene> resized;
    for (const PackedScene& s : scenes)
      resized.push_back(ResizePackedScene(s, width, height));
    std::map<std::string, bool> warmed;  // one untimed view per size and precision
    for (const int k : grid.ks) {
      double ulr_psnr = -1;
      for (const std::string& p : grid.precisions) {
        if (!nets.count(p)) continue;
        const std::string cell = std::to_string(width) + "x" + std::to_string(height) +
                                 " K=" + std::to_string(k) + " " + p;
        // Predicted from the last cell of this precision (or of any, at first), scaled
        // by K and the pixels.
        const double pixels = static_cast<double>(width) * height;
        auto it = rate.find(p);
        if (it == rate.end()) it = rate.begin();
        const double predicted = it == rate.end() ? 0 : it->second * k * pixels;
        if (size_clock.Seconds() + predicted > share) {
          skipped.push_back(cell + " (predicted " + std::to_string(predicted) +
                            " s, past the time bound)");
          continue;
        }
        FvsNet& net = nets.at(p);
        const torch::ScalarType dtype = PrecisionDtype(p);
        Timer cell_clock;
        Row row;
        row.width = width;
        row.height = height;
        row.k = k;
        row.precision = p;
        double ulr_sum = 0;
        for (const PackedScene& scene : resized) {
          for (const int target : ValidationTargets(scene, options.bench_views)) {
            const auto sources = SelectTrainingSources(scene, target, k);
            if (sources.empty()) continue;
            if (!warmed[p]) {
              RenderPackedView(net, scene, target, sources, warp, device, dtype, false);
              warmed[p] = true;
            }
            const PackedViewRender v = RenderPackedView(net, scene, target, sources, warp,
                                                        device, dtype, ulr_psnr < 0);
            row.warp_s += v.sample_s + v.warp_s;
            row.cpu_warp_s += v.sample_s;
            row.network_s += v.network_s;
            row.rest_s += v.rest_s;
            row.psnr += ScoreView(v.prediction, v.target, LpipsNet{nullptr}).psnr;
            if (ulr_psnr < 0)
              ulr_sum += ScoreView(v.ulr, v.target, LpipsNet{nullptr}).psnr;
            ++row.views;
          }
        }
        if (row.views == 0) continue;
        for (double* x :
             {&row.warp_s, &row.cpu_warp_s, &row.network_s, &row.rest_s, &row.psnr}) {
          *x /= row.views;
        }
        if (ulr_psnr < 0) ulr_psnr = ulr_sum / row.views;
        row.ulr_psnr = ulr_psnr;
        rate[p] = cell_clock.Seconds() / (k * pixels);
        rows.push_back(row);
        WriteCsv(csv, rows);
        std::printf("%4dx%-4d %2d %5s %5d %9.4f %9.4f %9.4f %9.4f %9.4f %8.2f %8.2f\n",
                    width, height, k, p.c_str(), row.views, row.warp_s, row.cpu_warp_s,
                    row.network_s, row.rest_s, row.total(), row.psnr, row.ulr_psnr);
        std::fflush(stdout);
      }
    }
  }
  for (const std::string& s : skipped) std::printf("skipped: %s\n", s.c_str());
  std::printf("wrote %s (%zu rows) in %.1f s\n", csv.c_str(), rows.size(),
              clock.Seconds());
  TrainSummary summary;
  summary.seconds = clock.Seconds();
  return summary;
}

}  // namespace fvs
