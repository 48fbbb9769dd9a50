#include "ui/live_view.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "fvs/util/cancel.h"
#include "fvs/util/error.h"

namespace fvs::ui {

double SteadySeconds() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void LiveViewOptions::Check() const {
  Require(min_fps > 0 && std::isfinite(min_fps), "live min_fps", "must be positive");
  Require(headroom > 0 && headroom <= 1, "live headroom", "must be in (0, 1]");
  Require(min_scale > 0 && min_scale <= initial_scale &&
              initial_scale <= max_live_scale && max_live_scale < 1,
          "live scales", "need 0 < min_scale <= initial_scale <= max_live_scale < 1");
  Require(live_max_sources >= 0, "live_max_sources", "must be >= 0");
  Require(live_selection_stride >= 1, "live_selection_stride", "must be >= 1");
  Require(settle_seconds >= 0, "live settle_seconds", "must be >= 0");
}

LiveScale::LiveScale(const LiveViewOptions& options)
    : options_(options), scale_(options.initial_scale) {}

void LiveScale::Observe(double scale, double seconds) {
  const double budget = options_.headroom / options_.min_fps;
  // Time grows with the pixels (scale squared); the fixed costs make small frames dearer
  // than that, which the next frames correct. Damped, so that one slow frame (a photo
  // read for the first time) does not halve the view, with a dead band against flicker
  // between two sizes.
  const double factor =
      std::clamp(std::sqrt(budget / std::max(seconds, 1e-4)), 0.7, 1.15);
  if (factor > 0.95 && factor < 1.05) return;
  scale_ = std::clamp(scale * factor, options_.min_scale, options_.max_live_scale);
}

std::vector<LiveLevel> LiveLevels(double live_scale, int full_width, int full_height,
                                  const NovelViewOptions& final_request,
                                  const LiveViewOptions& options) {
  // Below full size: the final method where it needs no network (ulr, nearest), else
  // ulr; the live frame also with fewer sources, the levels after it with the final K so
  // that they approach the final frame.
  NovelViewOptions sharpen = final_request;
  if (TraitsOfMethod(final_request.method).needs_weights) {
    sharpen.method = "ulr";
    sharpen.model_path.clear();
    sharpen.feature_cache_dir.clear();
    sharpen.scene_model_dir.clear();
  }
  NovelViewOptions live = sharpen;
  live.selection_stride = options.live_selection_stride;
  if (options.live_max_sources > 0) {
    live.max_num_sources = std::min(live.max_num_sources, options.live_max_sources);
    if (live.num_sources > 0)
      live.num_sources = std::min(live.num_sources, options.live_max_sources);
  }
  std::vector<LiveLevel> levels;
  // Doubling; a level past 0.65 of the full size would cost nearly the full frame and
  // is left out.
  for (double scale = live_scale; levels.empty() || scale <= 0.65; scale *= 2) {
    LiveLevel level;
    level.scale = scale;
    level.request = levels.empty() ? live : sharpen;
    level.request.width = std::max(8, static_cast<int>(std::lround(full_width * scale)));
    level.request.height =
        std::max(8, static_cast<int>(std::lround(full_height * scale)));
    levels.push_back(level);
  }
  LiveLevel full;
  full.request = final_request;
  full.request.width = full_width;
  full.request.height = full_height;
  levels.push_back(full);
  return levels;
}

LiveRenderer::LiveRenderer(std::shared_ptr<const Scene> scene,
                           const LiveViewOptions& options, FrameFn on_frame,
                           ErrorFn on_error)
    : scene_(std::move(scene)),
      options_(options),
      on_frame_(std::move(on_frame)),
      on_error_(std::move(on_error)),
      scale_(options) {
  options_.Check();
  Require(scene_ != nullptr, "live view", "no scene");
  thread_ = std::thread([this] { Loop(); });
}

LiveRenderer::~LiveRenderer() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    cancel_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

uint64_t LiveRenderer::Request(const PinholeCamera& camera,
                               const NovelViewOptions& final_request) {
  uint64_t id;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    id = next_id_++;
    pose_ = Pose{id, camera, final_request, SteadySeconds()};
    // A live frame in flight finishes (cancelling it at every mouse move would show
    // nothing while moving); a sharpening one is dropped.
    if (in_flight_level_ > 0) cancel_ = true;
  }
  wake_.notify_all();
  return id;
}

void LiveRenderer::Pause() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pose_.reset();
    cancel_ = true;
  }
  wake_.notify_all();
}

int LiveRenderer::num_dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return num_dropped_;
}

double LiveRenderer::live_scale() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return scale_.scale();
}

void LiveRenderer::Loop() {
  uint64_t rendered_id = 0;  // the pose whose levels are below
  std::vector<LiveLevel> levels;
  size_t next_level = 0;
  for (;;) {
    Pose pose;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      for (;;) {
        if (stop_) return;
        if (pose_ && pose_->id != rendered_id) break;  // a new pose: its live frame
        if (pose_ && next_level < levels.size()) {     // sharpen once it settled
          const double wait =
              pose_->requested_at + options_.settle_seconds - SteadySeconds();
          if (wait <= 0) break;
          wake_.wait_for(lock, std::chrono::duration<double>(wait));
          continue;
        }
        wake_.wait(lock);
      }
      pose = *pose_;
      if (pose.id != rendered_id) {
        rendered_id = pose.id;
        next_level = 0;
        levels = LiveLevels(scale_.scale(), pose.camera.width, pose.camera.height,
                            pose.final_request, options_);
      }
      in_flight_level_ = static_cast<int>(next_level);
      cancel_ = false;
    }
    const Outcome outcome =
        RenderLevel(pose, levels[next_level], static_cast<int>(next_level),
                    static_cast<int>(levels.size()));
    std::lock_guard<std::mutex> lock(mutex_);
    in_flight_level_ = -1;
    if (outcome == Outcome::kDone) ++next_level;
    // A failed render gives the pose up; a cancelled one is retried unless a new pose
    // (or a pause) replaced it, which the wait above sees.
    if (outcome == Outcome::kFailed) next_level = levels.size();
  }
}

LiveRenderer::Outcome LiveRenderer::RenderLevel(const Pose& pose, const LiveLevel& level,
                                                int index, int num_levels) {
  auto frame = std::make_shared<LiveFrame>();
  try {
    const CancelScope scope(&cancel_);
    const PinholeCamera camera =
        TargetCameraFor(pose.camera, level.request.width, level.request.height);
    frame->view = RenderNovelView(*scene_, camera, level.request);
  } catch (const Cancelled&) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++num_dropped_;
    return Outcome::kCancelled;
  } catch (const std::exception& e) {
    if (on_error_) on_error_(e.what());
    return Outcome::kFailed;
  }
  frame->pose_id = pose.id;
  frame->level = index;
  frame->num_levels = num_levels;
  frame->scale = level.scale;
  frame->seconds_since_request = SteadySeconds() - pose.requested_at;
  std::lock_guard<std::mutex> lock(mutex_);
  if (index == 0) scale_.Observe(level.scale, frame->view.seconds);
  // Delivered under the lock, so that no sharpening frame of a pose arrives after
  // Request has returned with a newer one (a live frame still does: it was asked for).
  if (index > 0 && (!pose_ || pose_->id != pose.id)) {
    ++num_dropped_;
    return Outcome::kCancelled;
  }
  if (on_frame_) on_frame_(frame);
  return Outcome::kDone;
}

}  // namespace fvs::ui
