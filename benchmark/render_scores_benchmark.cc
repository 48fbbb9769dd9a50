// Scores renders made outside this project (a peer's, e.g. Gaussian splats trained with
// OpenSplat by benchmark/peer_opensplat.sh) against a workspace's photos held out of the
// geometry, with the metrics `view_synthesis_eval` reports: PSNR and SSIM over the whole
// image (the render quantised to 8 bits, as eval does), LPIPS-alex when its weights are
// found. The photos are the workspace's undistorted ones (W/images), the frames eval
// scores against, so a peer's figures go beside ours unchanged.
//
// Usage: render_scores_benchmark --workspace_path W --renders_path R [--lpips_path P]
//                                [--seconds S] [--label L]
//   R holds <photo name>.png for each line of W/fvs/holdout.txt (a missing render is an
//   error, never skipped). Prints one row per view and the mean, and writes R/scores.csv.
//   --seconds and --label only go into the printed table (training time of the peer).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "colmap_ext/image_io.h"
#include "fvs/eval/lpips.h"
#include "fvs/eval/metrics.h"
#include "fvs/net/lpips_weights.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"

namespace {

namespace fs = std::filesystem;

struct Args {
  std::string workspace_path, renders_path, lpips_path, label = "peer";
  double seconds = -1;
};

Args Parse(int argc, char** argv) {
  const char* usage =
      "Usage: render_scores_benchmark --workspace_path W --renders_path R "
      "[--lpips_path P] [--seconds S] [--label L]";
  fvs::benchmark::CheckArgs(
      argc, argv, usage,
      {"--workspace_path", "--renders_path", "--lpips_path", "--seconds", "--label"});
  Args a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--workspace_path") a.workspace_path = value;
    if (key == "--renders_path") a.renders_path = value;
    if (key == "--lpips_path") a.lpips_path = value;
    if (key == "--seconds") a.seconds = std::stod(value);
    if (key == "--label") a.label = value;
  }
  if (a.workspace_path.empty() || a.renders_path.empty()) {
    std::fprintf(stderr, "ERROR: --workspace_path and --renders_path are required\n%s\n",
                 usage);
    std::exit(2);
  }
  return a;
}

std::vector<std::string> HeldOutNames(const std::string& workspace) {
  const std::string path = workspace + "/fvs/holdout.txt";
  std::ifstream in(path);
  if (!in) throw fvs::Error(path + ": cannot open (prepare with --holdout_images)");
  std::vector<std::string> names;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) names.push_back(line);
  }
  if (names.empty()) throw fvs::Error(path + ": no photo held out");
  return names;
}

struct Score {
  double psnr = 0, ssim = 0, lpips = -1;
};

Score ScoreView(const std::string& truth_path, const std::string& render_path,
                const fvs::eval::PerceptualDistance& lpips) {
  const fvs::Image truth = fvs::colmap::ReadImage(truth_path);
  if (!fs::exists(render_path))
    throw fvs::Error(render_path + ": no render of this view");
  const fvs::Image render =
      fvs::eval::QuantizeTo8Bit(fvs::colmap::ReadImage(render_path));
  if (render.width != truth.width || render.height != truth.height) {
    throw fvs::Error(render_path + ": " + std::to_string(render.width) + "x" +
                     std::to_string(render.height) + ", but the photo is " +
                     std::to_string(truth.width) + "x" + std::to_string(truth.height));
  }
  Score s;
  s.psnr = fvs::eval::Psnr(render, truth);
  s.ssim = fvs::eval::Ssim(render, truth);
  if (lpips) s.lpips = lpips(render, truth);
  return s;
}

int Run(const Args& a) {
  std::string why_not;
  const std::string lpips_path = fvs::ResolveLpipsPath(a.lpips_path);
  const fvs::eval::PerceptualDistance lpips =
      lpips_path.empty() ? nullptr : fvs::eval::LoadLpips(lpips_path, &why_not);
  if (!why_not.empty())
    std::fprintf(stderr, "LPIPS not available: %s\n", why_not.c_str());
  std::printf("machine: %s\n", fvs::DescribeMachine().c_str());
  std::ofstream csv(a.renders_path + "/scores.csv");
  csv << "view,psnr,ssim,lpips\n";
  double psnr = 0, ssim = 0, lpips_sum = 0;
  const std::vector<std::string> names = HeldOutNames(a.workspace_path);
  for (const std::string& name : names) {
    const Score s = ScoreView(a.workspace_path + "/images/" + name,
                              a.renders_path + "/" + name + ".png", lpips);
    std::printf("%-28s %7.2f %7.4f %7.4f\n", name.c_str(), s.psnr, s.ssim, s.lpips);
    csv << name << "," << s.psnr << "," << s.ssim << "," << s.lpips << "\n";
    psnr += s.psnr / names.size();
    ssim += s.ssim / names.size();
    lpips_sum += s.lpips / names.size();
  }
  std::printf("%s mean of %zu held-out views: PSNR %.2f  SSIM %.4f  LPIPS %.4f",
              a.label.c_str(), names.size(), psnr, ssim, lpips ? lpips_sum : -1.0);
  if (a.seconds >= 0) std::printf("  (trained %.0f s)", a.seconds);
  std::printf("\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(Parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
}
