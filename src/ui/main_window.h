// The "Render novel view" application window (colmap view_synthesis_gui): a 3D view of
// the workspace, render settings, the rendered view beside its nearest source photo, and
// the camera-path panel. Everything slow runs on a TaskRunner thread with a progress bar
// and Cancel; every failure shows as a message in the window, which stays usable.
//
// Tests drive it as a person would: menu actions (triggered), buttons (QTest clicks,
// found by objectName), and a replaceable file chooser instead of modal dialogs.
#pragma once

#include <QMainWindow>
#include <QString>
#include <deque>
#include <functional>
#include <memory>

#include "ui/novel_view.h"
#include "ui/workspace_contents.h"

class QAction;
class QComboBox;
class QLabel;
class QLineEdit;
class QProgressBar;
class QPushButton;
class QSpinBox;

namespace fvs::ui {

class LiveRenderer;
struct LiveFrame;
class PathPanel;
class ResultPanel;
class SceneView;
class TaskRunner;

// What a file dialog is asked for.
enum class FileRole { kOpenWorkspace, kOpenWeights, kOpenPath, kSavePath, kRenderFolder };
// Returns the chosen path, or an empty string when the user cancels.
using FileChooser = std::function<QString(FileRole role, const QString& suggestion)>;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  // Starts loading a workspace on the worker thread; the result (or the error) shows in
  // the window. Returns an error message when it cannot start (empty when it started).
  QString OpenWorkspace(const QString& path);
  // Renders the current viewpoint with the chosen settings (the Render button / menu).
  void RenderCurrentView();
  void CancelTask();

  // The live view (View > Live novel view, on by default): while the camera moves the 3D
  // view shows the novel view at a resolution that holds the frame rate, sharpening to
  // the full size with the chosen method and K when it stops (ui/live_view.h). Paused
  // while another task runs.
  void SetLiveView(bool on);
  bool live_view() const;
  // The last live frame shown (null when none), and the frame rate of the live frames of
  // the last second.
  const std::shared_ptr<const LiveFrame>& live_frame() const { return live_frame_; }
  double live_fps() const;

  // Method and weights to start with (command-line options); an unknown method is
  // reported in the message bar.
  void SetInitialSettings(const QString& method, const QString& model_path);

  // Replaces the file dialogs (tests; a default uses QFileDialog).
  void SetFileChooser(FileChooser chooser) { file_chooser_ = std::move(chooser); }
  QString ChooseFile(FileRole role, const QString& suggestion);

  // Shows a message in the window's message bar: errors in red, notes in grey.
  void ShowError(const QString& text);
  void ShowNote(const QString& text);
  void ClearMessage();
  QString message() const;
  bool message_is_error() const { return message_is_error_; }

  bool busy() const;
  std::shared_ptr<const WorkspaceContents> contents() const { return contents_; }
  // The last rendered view (null before the first, or after opening a workspace).
  const std::shared_ptr<const RenderedView>& last_render() const { return last_render_; }
  SceneView* scene_view() const { return scene_view_; }
  PathPanel* path_panel() const { return path_panel_; }
  TaskRunner* task_runner() const { return runner_; }
  // The render settings as chosen in the panel.
  NovelViewOptions CurrentRequest() const;
  // Why the request cannot be rendered now (no workspace, no mesh, no weights, a bad
  // setting), empty when it can.
  QString CannotRenderReason(const NovelViewOptions& request) const;
  // The target camera of the current viewpoint at the chosen size (scene frame).
  PinholeCamera CurrentTargetCamera() const;

 private:
  void BuildMenus();
  QWidget* BuildControls();
  void ShowContents(std::shared_ptr<const WorkspaceContents> contents);
  void UpdateEnabled();
  void OnMethodChanged();
  void RequestLiveFrame();
  void ShowLiveFrame(std::shared_ptr<const LiveFrame> frame);
  void ResetLiveRenderer();

  std::shared_ptr<const WorkspaceContents> contents_;
  std::shared_ptr<const RenderedView> last_render_;
  FileChooser file_chooser_;
  bool message_is_error_ = false;

  TaskRunner* runner_ = nullptr;
  SceneView* scene_view_ = nullptr;
  PathPanel* path_panel_ = nullptr;
  QLabel* message_ = nullptr;
  QLabel* workspace_label_ = nullptr;
  QComboBox* method_ = nullptr;
  QLineEdit* model_path_ = nullptr;
  QSpinBox* num_sources_ = nullptr;
  QSpinBox* width_ = nullptr;
  QSpinBox* height_ = nullptr;
  QPushButton* render_button_ = nullptr;
  QPushButton* cancel_button_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QLabel* progress_label_ = nullptr;
  ResultPanel* result_panel_ = nullptr;
  QAction* render_action_ = nullptr;
  QAction* cancel_action_ = nullptr;
  QAction* live_action_ = nullptr;

  std::unique_ptr<LiveRenderer> live_;
  uint64_t live_epoch_ = 0;  // frames posted by an earlier renderer are dropped
  std::shared_ptr<const LiveFrame> live_frame_;
  std::deque<double>
      live_arrivals_;  // steady seconds of the live frames of the last second
};

// Sets the OpenGL format every window of the application uses (3.3 core, depth buffer).
// Call before creating the QApplication.
void SetDefaultSurfaceFormat();

}  // namespace fvs::ui
