#include "ui/path_panel.h"

#include <QAction>
#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QListWidget>
#include <QPushButton>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <filesystem>

#include "colmap_ext/workspace.h"
#include "fvs/controllers/render_frames.h"
#include "fvs/path/video.h"
#include "fvs/render/method.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"
#include "ui/main_window.h"
#include "ui/scene_view.h"
#include "ui/task_runner.h"

namespace fvs::ui {
namespace {

// Frames -> path.mp4 with fvs/path's encoder (ffmpeg, when there is one). Returns a
// one-line note for the window.
QString MakeVideo(const std::vector<std::string>& frame_paths, const std::string& folder,
                  double fps) {
  if (FindFfmpeg().empty()) {
    return "ffmpeg is not on the PATH, so no mp4 was made (install ffmpeg and render "
           "again, or encode the PNG frames yourself).";
  }
  // A failed encoding loses no frames: it is reported beside them, not as a failed
  // render.
  try {
    const VideoResult video = EncodeVideo(frame_paths, fps, folder + "/path.mp4");
    return QString::fromStdString(video.written ? "Video: " + folder + "/path.mp4"
                                                : video.note);
  } catch (const std::exception& e) {
    return QString("The frames are there, but no mp4: ") + e.what();
  }
}

}  // namespace

PathPanel::PathPanel(MainWindow* window, QWidget* parent)
    : QGroupBox("Camera path", parent), window_(window) {
  setObjectName("path_panel");
  auto* layout = new QVBoxLayout(this);
  list_ = new QListWidget(this);
  list_->setObjectName("keyframe_list");
  list_->setMinimumHeight(100);
  connect(list_, &QListWidget::itemDoubleClicked, this,
          [this] { LookThroughSelected(); });
  layout->addWidget(list_, 1);

  auto* grid = new QGridLayout();
  const struct {
    const char* text;
    const char* name;
    void (PathPanel::*slot)();
    const char* button_text;
  } entries[] = {
      {"&Add current view as keyframe", "add_keyframe", &PathPanel::AddCurrentView,
       "Add view"},
      {"&Delete keyframe", "delete_keyframe", &PathPanel::DeleteSelected, "Delete"},
      {"Move keyframe &up", "move_keyframe_up", nullptr, "Up"},
      {"Move keyframe do&wn", "move_keyframe_down", nullptr, "Down"},
      {"&Preview path", "preview_path", &PathPanel::Preview, "Preview"},
      {"&Save path...", "save_path", &PathPanel::Save, "Save..."},
      {"&Load path...", "load_path", &PathPanel::Load, "Load..."},
      {"&Render path...", "render_path", &PathPanel::RenderPath, "Render path..."},
  };
  int i = 0;
  for (const auto& e : entries) {
    QAction* action = new QAction(e.text, this);
    action->setObjectName(QString("action_") + e.name);
    if (e.slot) {
      connect(action, &QAction::triggered, this, e.slot);
    } else {
      const int delta = QString(e.name).endsWith("up") ? -1 : 1;
      connect(action, &QAction::triggered, this, [this, delta] { MoveSelected(delta); });
    }
    auto* button = new QPushButton(e.button_text, this);
    button->setObjectName(QString(e.name) + "_button");
    connect(button, &QPushButton::clicked, action, &QAction::trigger);
    connect(action, &QAction::changed, button,
            [button, action] { button->setEnabled(action->isEnabled()); });
    grid->addWidget(button, i / 2, i % 2);
    actions_.push_back(action);
    buttons_.push_back(button);
    addAction(action);
    ++i;
  }
  actions_[0]->setShortcut(Qt::CTRL | Qt::Key_K);
  layout->addLayout(grid);

  auto* form = new QFormLayout();
  seconds_per_key_ = new QDoubleSpinBox(this);
  seconds_per_key_->setObjectName("seconds_per_keyframe");
  seconds_per_key_->setRange(0.1, 60);
  seconds_per_key_->setValue(2);
  seconds_per_key_->setSuffix(" s");
  form->addRow("Per keyframe", seconds_per_key_);
  fps_ = new QSpinBox(this);
  fps_->setObjectName("fps");
  fps_->setRange(1, 120);
  fps_->setValue(30);
  form->addRow("Frames per second", fps_);
  smooth_ = new QCheckBox("Smooth (Ceres)", this);
  smooth_->setObjectName("smooth");
  smooth_->setChecked(true);
  form->addRow(smooth_);
  layout->addLayout(form);

  preview_timer_ = new QTimer(this);
  connect(preview_timer_, &QTimer::timeout, this, [this] {
    if (preview_index_ >= preview_frames_.size()) {
      StopPreview();
      return;
    }
    window_->scene_view()->camera().LookThrough(
        preview_frames_[preview_index_],
        window_->scene_view()->camera().focus_distance());
    window_->scene_view()->update();
    ++preview_index_;
  });
  UpdateEnabled(false, false);
}

void PathPanel::SetContents(std::shared_ptr<const WorkspaceContents> contents) {
  StopPreview();
  contents_ = std::move(contents);
  keyframes_.clear();
  preview_frames_.clear();
  next_key_number_ = 1;
  RefreshList(-1);
}

void PathPanel::UpdateEnabled(bool busy, bool can_render) {
  const bool open = contents_ != nullptr;
  const bool keys = !keyframes_.empty();
  for (QAction* a : actions_) {
    const QString name = a->objectName();
    bool enabled = open && !busy;
    if (name == "action_load_path") {
      enabled = open && !busy;
    } else if (name != "action_add_keyframe") {
      enabled = enabled && keys;
    }
    if (name == "action_render_path") enabled = enabled && can_render;
    a->setEnabled(enabled);
  }
}

CameraPathOptions PathPanel::Options() const {
  CameraPathOptions options;
  options.fps = fps_->value();
  options.seconds_per_keyframe = seconds_per_key_->value();
  options.smooth = smooth_->isChecked();
  const NovelViewOptions request = window_->CurrentRequest();
  options.width = request.width;
  options.height = request.height;
  return options;
}

bool PathPanel::previewing() const { return preview_timer_->isActive(); }

void PathPanel::RefreshList(int select) {
  list_->clear();
  for (const CameraPathKeyframe& k : keyframes_) {
    const Eigen::Vector3d c = k.camera.Center();
    list_->addItem(QString("%1   (%2, %3, %4)")
                       .arg(QString::fromStdString(k.name))
                       .arg(c.x(), 0, 'f', 2)
                       .arg(c.y(), 0, 'f', 2)
                       .arg(c.z(), 0, 'f', 2));
  }
  if (select >= 0 && select < list_->count()) list_->setCurrentRow(select);
  ShowKeyframes();
  UpdateEnabled(window_->busy(), contents_ && contents_->can_render());
}

void PathPanel::ShowKeyframes() {
  std::vector<PinholeCamera> cameras;
  if (contents_) {
    for (const CameraPathKeyframe& k : keyframes_) {
      cameras.push_back(contents_->ToScene(k.camera));
    }
  }
  window_->scene_view()->SetKeyframes(std::move(cameras));
}

void PathPanel::StopPreview() {
  preview_timer_->stop();
  preview_index_ = 0;
}

void PathPanel::AddCurrentView() {
  if (!contents_) {
    window_->ShowError("No workspace is open: File > Open workspace first.");
    return;
  }
  CameraPathKeyframe key;
  key.name = QString("key_%1").arg(next_key_number_++, 2, 10, QChar('0')).toStdString();
  key.camera = contents_->ToWorld(window_->CurrentTargetCamera());
  const int row = list_->currentRow();
  const int at = row >= 0 ? row + 1 : static_cast<int>(keyframes_.size());
  keyframes_.insert(keyframes_.begin() + at, key);
  preview_frames_.clear();
  window_->scene_view()->SetPathPreview({});
  RefreshList(at);
}

void PathPanel::DeleteSelected() {
  const int row = list_->currentRow();
  if (row < 0 || row >= static_cast<int>(keyframes_.size())) {
    window_->ShowError("Select a keyframe in the list first.");
    return;
  }
  keyframes_.erase(keyframes_.begin() + row);
  RefreshList(std::min(row, static_cast<int>(keyframes_.size()) - 1));
}

void PathPanel::MoveSelected(int delta) {
  const int row = list_->currentRow();
  const int to = row + delta;
  if (row < 0 || to < 0 || to >= static_cast<int>(keyframes_.size())) return;
  std::swap(keyframes_[row], keyframes_[to]);
  RefreshList(to);
}

void PathPanel::LookThroughSelected() {
  const int row = list_->currentRow();
  if (!contents_ || row < 0 || row >= static_cast<int>(keyframes_.size())) return;
  SceneView* view = window_->scene_view();
  view->camera().LookThrough(contents_->ToScene(keyframes_[row].camera),
                             view->camera().focus_distance());
  view->update();
}

void PathPanel::Preview() {
  if (keyframes_.empty()) {
    window_->ShowError("Add keyframes first (Add view takes the current viewpoint).");
    return;
  }
  StopPreview();
  const std::vector<CameraPathKeyframe> keys = keyframes_;
  const CameraPathOptions options = Options();
  std::shared_ptr<const WorkspaceContents> contents = contents_;
  window_->task_runner()->Start(
      "Computing the camera path",
      [this, keys, options, contents](const TaskRunner::Control&,
                                      const TaskRunner::ProgressFn&) {
        options.Check();
        auto result = std::make_shared<CameraPathResult>(
            ComputeCameraPath(keys, options, contents->scene.get()));
        return TaskRunner::Continuation([this, result, contents, options] {
          if (contents != contents_) return;
          preview_frames_.clear();
          std::vector<Eigen::Vector3d> centers;
          for (const TargetCamera& f : result->frames) {
            preview_frames_.push_back(contents->ToScene(f.camera));
            centers.push_back(preview_frames_.back().Center());
          }
          window_->scene_view()->SetPathPreview(std::move(centers));
          window_->ShowNote(
              QString("Path: %1 frames (%2 s at %3 fps); jerk %4 -> %5 after smoothing")
                  .arg(result->frames.size())
                  .arg(result->frames.size() / options.fps, 0, 'f', 1)
                  .arg(options.fps)
                  .arg(result->before.jerk, 0, 'g', 3)
                  .arg(result->after.jerk, 0, 'g', 3));
          preview_index_ = 0;
          preview_timer_->start(static_cast<int>(1000.0 / options.fps));
        });
      },
      [this](const QString& error) {
        window_->ShowError("Cannot compute the path: " + error);
      });
}

void PathPanel::Save() {
  if (keyframes_.empty()) {
    window_->ShowError("Add keyframes first: there is no path to save.");
    return;
  }
  const QString path = window_->ChooseFile(FileRole::kSavePath, "camera_path.json");
  if (path.isEmpty()) return;
  const std::vector<CameraPathKeyframe> keys = keyframes_;
  const CameraPathOptions options = Options();
  std::shared_ptr<const WorkspaceContents> contents = contents_;
  const std::string file = path.toStdString();
  window_->task_runner()->Start(
      "Saving the camera path",
      [this, keys, options, contents, file](const TaskRunner::Control&,
                                            const TaskRunner::ProgressFn&) {
        options.Check();
        const std::vector<TargetCamera> frames =
            InterpolateCameraPath(keys, options, contents->scene.get());
        WriteNerfstudioCameraPath(file, keys, frames, options);
        const size_t n = frames.size();
        return TaskRunner::Continuation([this, file, n, keys] {
          window_->ShowNote(QString("Saved %1 keyframes and %2 frames to %3")
                                .arg(keys.size())
                                .arg(n)
                                .arg(QString::fromStdString(file)));
        });
      },
      [this](const QString& error) {
        window_->ShowError("Cannot save the path: " + error);
      });
}

void PathPanel::Load() {
  if (!contents_) {
    window_->ShowError("No workspace is open: File > Open workspace first.");
    return;
  }
  const QString path = window_->ChooseFile(FileRole::kOpenPath, QString());
  if (path.isEmpty()) return;
  try {
    std::vector<CameraPathKeyframe> keys = ReadNerfstudioKeyframes(path.toStdString());
    Require(!keys.empty(), path.toStdString(), "the camera path has no keyframes");
    StopPreview();
    keyframes_ = std::move(keys);
    next_key_number_ = static_cast<int>(keyframes_.size()) + 1;
    preview_frames_.clear();
    window_->scene_view()->SetPathPreview({});
    RefreshList(0);
    window_->ShowNote(
        QString("Loaded %1 keyframes from %2").arg(keyframes_.size()).arg(path));
  } catch (const std::exception& e) {
    window_->ShowError(QString("Cannot load the camera path: ") + e.what());
  }
}

void PathPanel::RenderPath() {
  const NovelViewOptions request = window_->CurrentRequest();
  QString reason = window_->CannotRenderReason(request);
  if (reason.isEmpty() && keyframes_.empty()) reason = "Add keyframes first.";
  if (!reason.isEmpty()) {
    window_->ShowError(reason);
    return;
  }
  const QString folder = window_->ChooseFile(FileRole::kRenderFolder, QString());
  if (folder.isEmpty()) return;
  StopPreview();
  const std::vector<CameraPathKeyframe> keys = keyframes_;
  const CameraPathOptions options = Options();
  std::shared_ptr<const WorkspaceContents> contents = contents_;
  const std::string out = folder.toStdString();
  window_->task_runner()->Start(
      "Rendering the camera path",
      [this, keys, options, contents, out, request](
          const TaskRunner::Control& control, const TaskRunner::ProgressFn& report) {
        options.Check();
        request.Check();
        const Timer timer;
        const Scene& scene = *contents->scene;
        report(0, 0, "Computing the path");
        const std::vector<TargetCamera> frames =
            InterpolateCameraPath(keys, options, &scene);
        colmap::CreateDirectories(out);
        WriteNerfstudioCameraPath(out + "/camera_path.json", keys, frames, options);
        // Stable sources, as `colmap view_synthesis --stable_sources 1`: the previous
        // frame's sources are favoured, so the set does not flicker between frames.
        RenderOptions render_options = request.ToRenderOptions();
        render_options.source_hysteresis = 0.3;
        render_options.stable_source_order = true;
        std::unique_ptr<Method> method = CreateMethod(request.method, render_options);
        const int n = static_cast<int>(frames.size());
        // The command line's frame loop (controllers/render_frames.h), without resuming,
        // a report or the flicker it would show: every frame is rendered anew into the
        // chosen folder.
        std::vector<RenderFrame> jobs;
        std::vector<std::string> frame_paths;
        for (const TargetCamera& frame : frames) {
          jobs.push_back({frame, false});
          frame_paths.push_back(out + "/" + frame.name + ".png");
        }
        RenderFramesOptions frame_options;
        frame_options.output_path = out;
        frame_options.method = request.method;
        frame_options.temporal.measure_flicker = false;  // no report: as fast as before
        RenderFramesCallbacks callbacks;
        callbacks.cancelled = [&control] { return control.cancelled.load(); };
        callbacks.before_frame = [&report, n](size_t i) {
          report(static_cast<int>(i), n, QString("Frame %1 of %2").arg(i + 1).arg(n));
        };
        const RenderFramesResult rendered =
            RenderFrames(scene, method.get(), jobs, frame_options, callbacks);
        frame_paths.resize(rendered.rendered.size());
        report(n, n, "Encoding the video");
        const QString video =
            control.cancelled ? QString() : MakeVideo(frame_paths, out, options.fps);
        const double seconds = timer.Seconds();
        return TaskRunner::Continuation([this, n, out, seconds, video] {
          window_->ShowNote(
              QString("Rendered %1 frames to %2 in %3 s (%4 s per frame). %5")
                  .arg(n)
                  .arg(QString::fromStdString(out))
                  .arg(seconds, 0, 'f', 1)
                  .arg(seconds / std::max(n, 1), 0, 'f', 2)
                  .arg(video));
        });
      },
      [this](const QString& error) {
        window_->ShowError("Path render failed: " + error);
      });
}

}  // namespace fvs::ui
