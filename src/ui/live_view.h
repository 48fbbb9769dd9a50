// The live novel view: while the camera moves, the view is rendered from the photos at a
// reduced resolution chosen to hold a frame rate; when it stops, the same pose is
// rendered again at higher resolutions up to the full one with the chosen method and K
// (the last frame is exactly what `colmap view_synthesis` renders at that pose). A new
// pose drops a sharpening render at once (util/cancel.h). No Qt here: the window, the
// benchmark (benchmark/live_view_benchmark.cc) and the tests drive the same code.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "ui/novel_view.h"

namespace fvs::ui {

struct LiveViewOptions {
  double min_fps = 15;    // live frames at least this often while the camera moves
  double headroom = 0.7;  // aim at this share of the frame time (drawing needs the rest)
  double min_scale = 0.05, max_live_scale = 0.5, initial_scale = 0.2;
  // The live frames: `ulr` with at most this many sources (0 = the final request's K).
  int live_max_sources = 4;
  // ...ranked on every n-th pixel (ranking all photos is most of a small frame's time).
  int live_selection_stride = 2;
  // Seconds without a new pose before the view sharpens.
  double settle_seconds = 0.12;
  void Check() const;  // fvs::Error naming the setting out of range
};

// Chooses the live scale from the times of the last live frames: the pixels a frame
// may have so that it takes headroom / min_fps seconds.
class LiveScale {
 public:
  explicit LiveScale(const LiveViewOptions& options);
  double scale() const { return scale_; }
  // A live frame at `scale` took `seconds`.
  void Observe(double scale, double seconds);

 private:
  LiveViewOptions options_;
  double scale_;
};

// One level of the renders of a pose: 0 is the live frame, the last the full one.
struct LiveLevel {
  double scale = 1;
  NovelViewOptions request;  // method, K and size of this level
};
// The levels for a pose seen by a camera of full_width x full_height: the live scale,
// then twice that, ... up to 0.65 of the full size (ulr, or the final method where it
// needs no network), then the final request at full size.
std::vector<LiveLevel> LiveLevels(double live_scale, int full_width, int full_height,
                                  const NovelViewOptions& final_request,
                                  const LiveViewOptions& options);

struct LiveFrame {
  uint64_t pose_id = 0;  // the Request it answers
  int level = 0, num_levels = 1;
  double scale = 1;
  bool complete() const { return level + 1 == num_levels; }
  RenderedView view;
  double seconds_since_request = 0;  // latency: Request of this pose to this frame
};

// Renders on a thread of its own. on_frame is called on that thread with every frame
// (the window posts it to the GUI thread), with the renderer's lock held: it must not
// call back into the renderer. on_error gets the message of a failed render, after which
// the pose is given up until the next Request.
class LiveRenderer {
 public:
  using FrameFn = std::function<void(std::shared_ptr<const LiveFrame>)>;
  using ErrorFn = std::function<void(const std::string&)>;
  LiveRenderer(std::shared_ptr<const Scene> scene, const LiveViewOptions& options,
               FrameFn on_frame, ErrorFn on_error);
  ~LiveRenderer();  // drops the work in flight and joins the thread
  LiveRenderer(const LiveRenderer&) = delete;
  LiveRenderer& operator=(const LiveRenderer&) = delete;

  // A new pose (scene frame, full size) and the final method/K/weights: a live frame is
  // rendered as soon as the thread is free, and a sharpening render of an older pose is
  // dropped at once. Returns the pose's id (as in LiveFrame::pose_id).
  uint64_t Request(const PinholeCamera& camera, const NovelViewOptions& final_request);
  // Stops rendering (work in flight is dropped) until the next Request.
  void Pause();
  double live_scale() const;
  // Renders dropped before their end (a newer pose, a pause): cancelled mid-way or
  // finished too late to be shown.
  int num_dropped() const;

 private:
  struct Pose {
    uint64_t id = 0;
    PinholeCamera camera;
    NovelViewOptions final_request;
    double requested_at = 0;  // steady clock, seconds
  };
  enum class Outcome { kDone, kCancelled, kFailed };
  void Loop();
  Outcome RenderLevel(const Pose& pose, const LiveLevel& level, int index,
                      int num_levels);

  std::shared_ptr<const Scene> scene_;
  LiveViewOptions options_;
  FrameFn on_frame_;
  ErrorFn on_error_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Pose> pose_;  // the latest request
  uint64_t next_id_ = 1;
  bool stop_ = false;
  std::atomic<bool> cancel_{false};  // drops the render in flight
  int in_flight_level_ = -1;         // level being rendered, -1 = none
  int num_dropped_ = 0;
  LiveScale scale_;
  std::thread thread_;
};

double SteadySeconds();

}  // namespace fvs::ui
