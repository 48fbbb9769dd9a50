// The training losses' cost per sample: L1 + SSIM against L1 + LPIPS-alex, forward alone
// and forward + backward (gradient with respect to the prediction, as in training), on
// random crops of --crop pixels in batches of --batch, LibTorch on --threads CPU threads.
// Prints the median wall and CPU (all threads) milliseconds per sample of --runs runs
// beside the machine, and the loss values (so that a broken network shows). On a shared
// machine the CPU time is the steadier figure.
//
// Usage: lpips_benchmark [--weights P] [--crop 128] [--batch 1] [--runs 10] [--threads 2]
//   --weights: LPIPS weights (default $FVS_LPIPS_PATH, else ../shared/weights/
//              lpips_alex.safetensors from the working directory)
#include <time.h>
#include <torch/torch.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "fvs/net/lpips_net.h"
#include "fvs/train/loss.h"
#include "fvs/util/machine.h"
#include "fvs/util/progress.h"

namespace {

struct Args {
  std::string weights;
  int crop = 128, batch = 1, runs = 10, threads = 2;
};

Args Parse(int argc, char** argv) {
  const char* usage =
      "Usage: lpips_benchmark [--weights P] [--crop 128] [--batch 1] [--runs 10] "
      "[--threads 2]";
  fvs::benchmark::CheckArgs(argc, argv, usage,
                            {"--weights", "--crop", "--batch", "--runs", "--threads"});
  Args a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--weights") a.weights = value;
    if (key == "--crop") a.crop = std::stoi(value);
    if (key == "--batch") a.batch = std::stoi(value);
    if (key == "--runs") a.runs = std::stoi(value);
    if (key == "--threads") a.threads = std::stoi(value);
  }
  a.weights = fvs::ResolveLpipsPath(a.weights);
  if (a.weights.empty()) a.weights = "../shared/weights/lpips_alex.safetensors";
  return a;
}

double CpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

struct Cost {
  double wall_ms = 0, cpu_ms = 0;  // per sample, medians
};

// `runs` calls of the loss (one warm-up first); *value: the last second term.
Cost MsPerSample(fvs::TrainingLoss& loss, const Args& a, bool backward, double* value) {
  const torch::Tensor target = torch::rand({a.batch, 3, a.crop, a.crop});
  std::vector<double> wall, cpu;
  for (int run = 0; run <= a.runs; ++run) {
    const torch::Tensor prediction =
        torch::rand({a.batch, 3, a.crop, a.crop}).requires_grad_(backward);
    fvs::Timer timer;
    const double cpu_start = CpuSeconds();
    if (backward) {
      const fvs::LossValue l = loss(prediction, target);
      l.total.backward();
      *value = l.second;
    } else {
      torch::NoGradGuard no_grad;
      *value = loss(prediction, target).second;
    }
    if (run == 0) continue;
    wall.push_back(1000 * timer.Seconds() / a.batch);
    cpu.push_back(1000 * (CpuSeconds() - cpu_start) / a.batch);
  }
  return {Median(wall), Median(cpu)};
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = Parse(argc, argv);
  torch::set_num_threads(a.threads);
  std::printf("machine: %s, LibTorch threads %d; crop %d, batch %d, %d runs (median)\n",
              fvs::CpuModelName().c_str(), a.threads, a.crop, a.batch, a.runs);
  fvs::LossOptions ssim;
  fvs::LossOptions lpips;
  lpips.kind = "l1+lpips";
  try {
    lpips.lpips = fvs::LpipsNet(a.weights);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  for (const fvs::LossOptions& options : {ssim, lpips}) {
    fvs::TrainingLoss loss(options, torch::kCPU);
    double value = 0;
    const Cost forward = MsPerSample(loss, a, false, &value);
    const Cost both = MsPerSample(loss, a, true, &value);
    std::printf(
        "%-9s ms/sample wall (CPU): forward %7.2f (%7.2f), forward+backward %7.2f "
        "(%7.2f)  [%s %.4f]\n",
        loss.Name().c_str(), forward.wall_ms, forward.cpu_ms, both.wall_ms, both.cpu_ms,
        loss.SecondTermName().c_str(), value);
  }
  return 0;
}
