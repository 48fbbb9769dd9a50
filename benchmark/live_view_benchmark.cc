// The GUI's live view without a window (issue 45): the application's rendering path
// (ui/live_view.h, as the 3D view drives it) on a prepared workspace.
//  1. Fixed live scales: seconds per frame, frames per second and PSNR against the full
//     render of the same pose (upsampled bilinear, as eval scores scaled renders).
//  2. A scripted orbit: the camera moves at 30 poses per second for --seconds around
//     the scene's focus; frames per second delivered, latency from a pose to its frame,
//     and the live scale the controller settled on. Then the camera stops: the time to
//     each sharpening level and its PSNR against the complete frame.
//   live_view_benchmark --workspace_path W [--width 960 --height 540] [--seconds 8]
//                       [--method ulr] [--min_fps 15]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "fvs/eval/draw.h"
#include "fvs/eval/metrics.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "ui/live_view.h"
#include "ui/viewer_camera.h"
#include "ui/workspace_contents.h"

namespace {

using fvs::ui::LiveFrame;

double PsnrAgainst(const fvs::Image& frame, const fvs::Image& full) {
  const fvs::Image up = frame.width == full.width && frame.height == full.height
                            ? frame
                            : fvs::eval::ResizeImage(frame, full.width, full.height);
  return fvs::eval::Psnr(up, full);
}

// The orbit's pose at time t: yaw about the scene's up around the focus, +-amplitude.
fvs::PinholeCamera OrbitPose(const fvs::ui::ViewerCamera& start,
                             const Eigen::Vector3d& up, double t, double amplitude,
                             int width, int height) {
  fvs::ui::ViewerCamera camera = start;
  camera.Orbit(amplitude * std::sin(2.0 * M_PI * t / 6.0), 0.1 * amplitude * std::sin(t),
               up);
  return camera.ToPinhole(width, height);
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage =
      "usage: live_view_benchmark --workspace_path W [--width 960] [--height 540] "
      "[--seconds 8] [--method ulr] [--min_fps 15]";
  fvs::benchmark::CheckArgs(
      argc, argv, usage,
      {"--workspace_path", "--width", "--height", "--seconds", "--method", "--min_fps"});
  std::string workspace;
  int width = 960, height = 540;
  double seconds = 8, min_fps = 15;
  std::string method = "ulr";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--workspace_path") workspace = v;
    if (a == "--width") width = std::atoi(v.c_str());
    if (a == "--height") height = std::atoi(v.c_str());
    if (a == "--seconds") seconds = std::atof(v.c_str());
    if (a == "--method") method = v;
    if (a == "--min_fps") min_fps = std::atof(v.c_str());
  }
  if (workspace.empty()) {
    std::fprintf(stderr, "ERROR: --workspace_path is required\n%s\n", usage);
    return 2;
  }
  try {
    const fvs::ui::WorkspaceContents contents = fvs::ui::LoadWorkspace(workspace);
    if (!contents.can_render()) throw fvs::Error(workspace, contents.render_error);
    std::printf(
        "machine: %s\nworkspace: %s (%d views, %zu mesh faces), full size %dx%d, "
        "final method %s\n",
        fvs::DescribeMachine().c_str(), workspace.c_str(), contents.num_views(),
        contents.mesh.faces.size(), width, height, method.c_str());
    const fvs::PinholeCamera& first = contents.cameras.front();
    fvs::ui::ViewerCamera start;
    start.LookThrough(first, std::max(first.WorldToCamera(Eigen::Vector3d::Zero()).z(),
                                      0.25 * contents.scale));
    fvs::ui::NovelViewOptions final_request;
    final_request.method = method;
    fvs::ui::NovelViewOptions full_request = final_request;  // at the full size
    full_request.width = width;
    full_request.height = height;
    fvs::ui::LiveViewOptions options;
    options.min_fps = min_fps;
    const fvs::Scene& scene = *contents.scene;

    // 1. Fixed scales, rendered one after the other on this thread (photos read first).
    const double amplitude = 0.25;  // radians of yaw
    std::vector<fvs::PinholeCamera> poses;
    for (int i = 0; i < 6; ++i)
      poses.push_back(OrbitPose(start, contents.up, 0.5 + i, amplitude, width, height));
    std::vector<fvs::Image> full;
    double full_seconds = 0;
    for (const auto& pose : poses) {
      const auto view = fvs::ui::RenderNovelView(scene, pose, full_request);
      full.push_back(view.result.color);
      full_seconds += view.seconds;
    }
    std::printf("\nfull %s %dx%d: %.3f s per frame\n", method.c_str(), width, height,
                full_seconds / poses.size());
    std::printf("\nlive frames (ulr, <= %d sources) at fixed scales, %zu poses:\n",
                options.live_max_sources, poses.size());
    std::printf("%6s %10s %9s %7s %10s\n", "scale", "size", "s/frame", "fps",
                "PSNR/full");
    for (double scale : {0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5}) {
      const auto levels =
          fvs::ui::LiveLevels(scale, width, height, final_request, options);
      double total = 0, psnr = 0;
      fvs::RenderTimings split;
      for (size_t i = 0; i < poses.size(); ++i) {
        const auto& req = levels.front().request;
        const auto view = fvs::ui::RenderNovelView(
            scene, fvs::ui::TargetCameraFor(poses[i], req.width, req.height), req);
        total += view.seconds;
        split.depth_s += view.result.timings.depth_s / poses.size();
        split.selection_s += view.result.timings.selection_s / poses.size();
        split.warp_s += view.result.timings.warp_s / poses.size();
        split.blend_s += view.result.timings.blend_s / poses.size();
        psnr += PsnrAgainst(view.result.color, full[i]);
      }
      const auto& req = levels.front().request;
      std::printf("%6.2f %5dx%-4d %9.4f %7.1f %10.2f   %.4f / %.4f / %.4f / %.4f\n",
                  scale, req.width, req.height, total / poses.size(),
                  poses.size() / total, psnr / poses.size(), split.depth_s,
                  split.selection_s, split.warp_s, split.blend_s);
    }

    // 2. The orbit through LiveRenderer, as the window drives it.
    std::mutex mutex;
    std::vector<std::shared_ptr<const LiveFrame>> frames;
    std::vector<double> arrival;
    fvs::ui::LiveRenderer live(
        contents.scene, options,
        [&](std::shared_ptr<const LiveFrame> frame) {
          std::lock_guard<std::mutex> lock(mutex);
          frames.push_back(frame);
          arrival.push_back(fvs::ui::SteadySeconds());
        },
        [](const std::string& error) {
          std::fprintf(stderr, "render failed: %s\n", error.c_str());
        });
    const double t0 = fvs::ui::SteadySeconds();
    uint64_t last_id = 0;
    std::vector<std::pair<uint64_t, double>> requests;  // pose id, when asked for
    fvs::PinholeCamera last_pose;
    for (int step = 0;; ++step) {
      const double t = step / 30.0;
      if (t > seconds) break;
      last_pose = OrbitPose(start, contents.up, t, amplitude, width, height);
      last_id = live.Request(last_pose, final_request);
      requests.emplace_back(last_id, fvs::ui::SteadySeconds());
      std::this_thread::sleep_until(
          std::chrono::steady_clock::now() +
          std::chrono::duration<double>(t0 + (step + 1) / 30.0 -
                                        fvs::ui::SteadySeconds()));
    }
    const double t_stop = fvs::ui::SteadySeconds();
    // Wait for the last pose to sharpen completely.
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      std::lock_guard<std::mutex> lock(mutex);
      if (!frames.empty() && frames.back()->pose_id == last_id &&
          frames.back()->complete())
        break;
      if (fvs::ui::SteadySeconds() - t_stop > 120) throw fvs::Error("no complete frame");
    }
    std::lock_guard<std::mutex> lock(mutex);
    int moving = 0;
    double latency = 0, latency_max = 0, scale_sum = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
      if (frames[i]->level != 0 || arrival[i] > t_stop) continue;
      // Warm-up: the first second reads photos for the first time.
      if (arrival[i] - t0 < 1.0) continue;
      ++moving;
      latency += frames[i]->seconds_since_request;
      latency_max = std::max(latency_max, frames[i]->seconds_since_request);
      scale_sum += frames[i]->scale;
    }
    const double span = t_stop - t0 - 1.0;
    // Camera change -> the first frame that shows it or a later pose (most poses are
    // superseded before the thread is free: their change shows in a later pose's frame).
    double change_sum = 0, change_max = 0;
    int changes = 0;
    for (const auto& [id, asked] : requests) {
      if (asked - t0 < 1.0) continue;
      for (size_t i = 0; i < frames.size(); ++i) {
        if (frames[i]->pose_id < id) continue;
        change_sum += arrival[i] - asked;
        change_max = std::max(change_max, arrival[i] - asked);
        ++changes;
        break;
      }
    }
    std::printf(
        "camera change -> first frame showing it: mean %.3f s, max %.3f s (%d changes)\n",
        changes ? change_sum / changes : 0.0, change_max, changes);
    std::printf(
        "\norbit: %.1f s at 30 poses/s (first second not counted): %.1f live frames "
        "per second, latency pose -> frame mean %.3f s, max %.3f s, mean live "
        "scale %.2f (%dx%d)\n",
        seconds, moving / span, moving ? latency / moving : 0.0, latency_max,
        moving ? scale_sum / moving : 0.0,
        static_cast<int>(std::lround(width * (moving ? scale_sum / moving : 0))),
        static_cast<int>(std::lround(height * (moving ? scale_sum / moving : 0))));
    const fvs::Image& complete = frames.back()->view.result.color;
    std::printf(
        "\nafter the stop (pose %llu): level, size, seconds after the stop, render s, "
        "PSNR against the complete frame\n",
        static_cast<unsigned long long>(last_id));
    for (size_t i = 0; i < frames.size(); ++i) {
      if (frames[i]->pose_id != last_id) continue;
      const auto& c = frames[i]->view.camera;
      std::printf("  %d/%d %5dx%-4d %7.3f s %7.3f s %8.2f dB%s\n", frames[i]->level + 1,
                  frames[i]->num_levels, c.width, c.height, arrival[i] - t_stop,
                  frames[i]->view.seconds,
                  PsnrAgainst(frames[i]->view.result.color, complete),
                  frames[i]->complete() ? " (complete)" : "");
    }
    // The complete frame is the command line's render at that pose.
    const auto reference = fvs::ui::RenderNovelView(scene, last_pose, full_request);
    double max_diff = 0;
    for (size_t i = 0; i < complete.data.size(); ++i)
      max_diff = std::max<double>(
          max_diff, std::abs(complete.data[i] - reference.result.color.data[i]));
    std::printf(
        "complete frame against a direct render of the pose: max difference %.2g\n",
        max_diff);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
}
