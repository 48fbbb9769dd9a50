// The camera-path panel: keyframes taken from the current view (WORLD frame, as
// camera_path.json holds them), listed, reordered and deleted; the interpolated path
// (fvs/path: Catmull-Rom/squad + Ceres smoothing) previewed in the 3D view; saved and
// loaded as nerfstudio camera_path.json; rendered to frames (and to mp4 when ffmpeg is on
// the PATH) on the worker thread with progress and Cancel between frames.
#pragma once

#include <QGroupBox>
#include <QString>
#include <memory>
#include <vector>

#include "fvs/path/camera_path.h"
#include "ui/workspace_contents.h"

class QAction;
class QCheckBox;
class QDoubleSpinBox;
class QListWidget;
class QPushButton;
class QSpinBox;
class QTimer;

namespace fvs::ui {

class MainWindow;

class PathPanel : public QGroupBox {
  Q_OBJECT

 public:
  PathPanel(MainWindow* window, QWidget* parent);

  // A new workspace: keyframes and preview are cleared.
  void SetContents(std::shared_ptr<const WorkspaceContents> contents);
  void UpdateEnabled(bool busy, bool can_render);

  void AddCurrentView();
  void DeleteSelected();
  void MoveSelected(int delta);  // -1 up, +1 down
  void LookThroughSelected();
  void Preview();
  void Save();
  void Load();
  void RenderPath();

  const std::vector<CameraPathKeyframe>& keyframes() const { return keyframes_; }
  CameraPathOptions Options() const;
  bool previewing() const;
  // Frames of the last computed path (scene frame), for the preview.
  const std::vector<PinholeCamera>& preview_frames() const { return preview_frames_; }

 private:
  void RefreshList(int select);
  void ShowKeyframes();
  void StopPreview();
  QAction* AddPathAction(const QString& text, const QString& name,
                         void (PathPanel::*slot)());

  MainWindow* window_;
  std::shared_ptr<const WorkspaceContents> contents_;
  std::vector<CameraPathKeyframe> keyframes_;
  int next_key_number_ = 1;
  std::vector<PinholeCamera> preview_frames_;
  size_t preview_index_ = 0;

  QListWidget* list_ = nullptr;
  QDoubleSpinBox* seconds_per_key_ = nullptr;
  QSpinBox* fps_ = nullptr;
  QCheckBox* smooth_ = nullptr;
  QTimer* preview_timer_ = nullptr;
  std::vector<QPushButton*> buttons_;
  std::vector<QAction*> actions_;
};

}  // namespace fvs::ui
