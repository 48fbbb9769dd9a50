#include "ui/main_window.h"

#include <QAction>
#include <QComboBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QMenuBar>
#include <QMetaObject>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QSplitter>
#include <QStatusBar>
#include <QSurfaceFormat>
#include <QToolButton>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "fvs/render/fvs_method.h"
#include "fvs/render/method.h"
#include "fvs/scene/photo_quality.h"
#include "fvs/scene/scene.h"
#include "fvs/util/cancel.h"
#include "fvs/util/error.h"
#include "fvs/util/folder_lock.h"
#include "ui/image_view.h"
#include "ui/live_view.h"
#include "ui/path_panel.h"
#include "ui/result_panel.h"
#include "ui/scene_view.h"
#include "ui/task_runner.h"

namespace fvs::ui {
namespace {

bool MethodNeedsWeights(const std::string& method) {
  return TraitsOfMethod(method).needs_weights;
}

// Default output size: the first camera's, at most 640 pixels wide (a few seconds per
// view on a laptop CPU).
void DefaultSize(const WorkspaceContents& w, int* width, int* height) {
  *width = 640;
  *height = 480;
  if (w.cameras.empty()) return;
  const PinholeCamera& c = w.cameras.front();
  const double scale = std::min(1.0, 640.0 / c.width);
  *width = std::max(8, static_cast<int>(std::lround(c.width * scale)));
  *height = std::max(8, static_cast<int>(std::lround(c.height * scale)));
}

}  // namespace

void SetDefaultSurfaceFormat() {
  QSurfaceFormat format;
  format.setVersion(3, 3);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  format.setSamples(0);
  QSurfaceFormat::setDefaultFormat(format);
}

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent) {
  setWindowTitle("COLMAP - Render novel view");
  runner_ = new TaskRunner(this);

  auto* central = new QWidget(this);
  auto* layout = new QVBoxLayout(central);
  layout->setContentsMargins(4, 4, 4, 4);
  message_ = new QLabel(central);
  message_->setObjectName("message");
  message_->setWordWrap(true);
  message_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  message_->hide();
  layout->addWidget(message_);

  auto* main_split = new QSplitter(Qt::Horizontal, central);
  auto* left_split = new QSplitter(Qt::Vertical, main_split);
  scene_view_ = new SceneView(left_split);
  scene_view_->setObjectName("scene_view");
  left_split->addWidget(scene_view_);
  result_panel_ = new ResultPanel(scene_view_, left_split);
  result_panel_->setObjectName("result_panel");
  left_split->addWidget(result_panel_);
  left_split->setStretchFactor(0, 3);
  left_split->setStretchFactor(1, 2);
  left_split->setSizes({460, 340});
  main_split->addWidget(left_split);
  main_split->addWidget(BuildControls());
  main_split->setStretchFactor(0, 1);
  main_split->setStretchFactor(1, 0);
  layout->addWidget(main_split, 1);
  setCentralWidget(central);
  BuildMenus();
  scene_view_->SetLiveEnabled(live_action_->isChecked());

  connect(runner_, &TaskRunner::progress, this,
          [this](int done, int total, const QString& text) {
            progress_->setRange(0, std::max(total, 0));
            progress_->setTextVisible(total > 0);
            if (total > 0) progress_->setValue(done);
            progress_label_->setText(text);
          });
  connect(runner_, &TaskRunner::started, this, [this] {
    if (live_) live_->Pause();  // the task gets the cores
    UpdateEnabled();
  });
  connect(runner_, &TaskRunner::stopped, this, [this](bool cancelled) {
    progress_->setRange(0, 1);
    progress_->setValue(0);
    progress_->setTextVisible(false);
    progress_label_->setText(cancelled ? "Cancelled" : "");
    UpdateEnabled();
    RequestLiveFrame();
  });
  connect(scene_view_, &SceneView::viewChanged, this, [this] { RequestLiveFrame(); });
  connect(scene_view_, &SceneView::cameraClicked, this, [this](int index) {
    if (!contents_) return;
    statusBar()->showMessage("Looking through " +
                             QString::fromStdString(contents_->view_names.at(index)));
  });
  resize(1240, 860);
  UpdateEnabled();
  statusBar()->showMessage("File > Open workspace to start");
}

// The live renderer's thread joins before the widgets go.
MainWindow::~MainWindow() { live_.reset(); }

void MainWindow::BuildMenus() {
  QMenu* file = menuBar()->addMenu("&File");
  QAction* open = file->addAction("&Open workspace...", this, [this] {
    const QString path = ChooseFile(FileRole::kOpenWorkspace, QString());
    if (path.isEmpty()) return;
    const QString error = OpenWorkspace(path);
    if (!error.isEmpty()) ShowError(error);
  });
  open->setObjectName("action_open");
  open->setShortcut(QKeySequence::Open);
  file->addSeparator();
  QAction* quit = file->addAction("&Quit", this, &QWidget::close);
  quit->setShortcut(QKeySequence::Quit);

  QMenu* view = menuBar()->addMenu("&View");
  auto add_toggle = [&](const QString& text, const QString& name, auto setter) {
    QAction* action = view->addAction(text);
    action->setObjectName(name);
    action->setCheckable(true);
    action->setChecked(true);
    connect(action, &QAction::toggled, scene_view_, setter);
  };
  add_toggle("Show sparse &points", "action_show_points", &SceneView::SetShowPoints);
  add_toggle("Show &cameras", "action_show_cameras", &SceneView::SetShowCameras);
  add_toggle("Show proxy &mesh", "action_show_mesh", &SceneView::SetShowMesh);
  view->addSeparator();
  QAction* reset = view->addAction("&Reset view", scene_view_, &SceneView::ResetView);
  reset->setObjectName("action_reset_view");
  QAction* overview = view->addAction("&Overview", scene_view_, &SceneView::ShowOverview);
  overview->setObjectName("action_overview");
  view->addSeparator();
  live_action_ = view->addAction("&Live novel view");
  live_action_->setObjectName("action_live_view");
  live_action_->setCheckable(true);
  live_action_->setChecked(true);
  live_action_->setToolTip(
      "Show the view rendered from the photos while the camera moves (reduced "
      "resolution), sharpening to full size when it stops");
  connect(live_action_, &QAction::toggled, this, [this](bool on) { SetLiveView(on); });

  QMenu* render = menuBar()->addMenu("&Render");
  render_action_ =
      render->addAction("Render &novel view", this, &MainWindow::RenderCurrentView);
  render_action_->setObjectName("action_render");
  render_action_->setShortcut(Qt::CTRL | Qt::Key_R);
  cancel_action_ = render->addAction("&Cancel", this, &MainWindow::CancelTask);
  cancel_action_->setObjectName("action_cancel");

  QMenu* path = menuBar()->addMenu("&Path");
  for (QAction* action : path_panel_->actions()) path->addAction(action);
}

QWidget* MainWindow::BuildControls() {
  auto* panel = new QWidget(this);
  panel->setMinimumWidth(300);
  panel->setMaximumWidth(380);
  auto* layout = new QVBoxLayout(panel);
  layout->setContentsMargins(4, 0, 0, 0);

  workspace_label_ = new QLabel("No workspace", panel);
  workspace_label_->setObjectName("workspace_label");
  workspace_label_->setWordWrap(true);
  layout->addWidget(workspace_label_);

  auto* render_box = new QGroupBox("Render novel view", panel);
  auto* form = new QFormLayout(render_box);
  method_ = new QComboBox(render_box);
  method_->setObjectName("method");
  for (const std::string& name : RegisteredMethods()) {
    method_->addItem(QString::fromStdString(name));
  }
  method_->setCurrentText("ulr");
  connect(method_, &QComboBox::currentTextChanged, this, [this] { OnMethodChanged(); });
  form->addRow("Method", method_);

  auto* weights_row = new QHBoxLayout();
  model_path_ = new QLineEdit(render_box);
  model_path_->setObjectName("model_path");
  model_path_->setPlaceholderText("weights (.safetensors), fvs methods only");
  auto* browse = new QToolButton(render_box);
  browse->setText("...");
  connect(browse, &QToolButton::clicked, this, [this] {
    const QString path = ChooseFile(FileRole::kOpenWeights, model_path_->text());
    if (!path.isEmpty()) model_path_->setText(path);
  });
  weights_row->addWidget(model_path_);
  weights_row->addWidget(browse);
  form->addRow("Weights", weights_row);

  num_sources_ = new QSpinBox(render_box);
  num_sources_->setObjectName("num_sources");
  num_sources_->setRange(0, 16);
  num_sources_->setSpecialValueText("auto");  // 0: adaptive K (RenderOptions)
  num_sources_->setValue(0);                  // auto
  connect(num_sources_, qOverload<int>(&QSpinBox::valueChanged), this,
          [this] { RequestLiveFrame(); });
  form->addRow("Sources (K)", num_sources_);
  auto* size_row = new QHBoxLayout();
  width_ = new QSpinBox(render_box);
  width_->setObjectName("width");
  height_ = new QSpinBox(render_box);
  height_->setObjectName("height");
  for (QSpinBox* s : {width_, height_}) {
    s->setRange(8, 8192);
    s->setSingleStep(16);
    size_row->addWidget(s);
  }
  width_->setValue(640);
  height_->setValue(480);
  form->addRow("Resolution", size_row);

  auto* buttons = new QHBoxLayout();
  render_button_ = new QPushButton("Render", render_box);
  render_button_->setObjectName("render_button");
  render_button_->setToolTip("Render the current viewpoint (Ctrl+R)");
  cancel_button_ = new QPushButton("Cancel", render_box);
  cancel_button_->setObjectName("cancel_button");
  connect(render_button_, &QPushButton::clicked, this, &MainWindow::RenderCurrentView);
  connect(cancel_button_, &QPushButton::clicked, this, &MainWindow::CancelTask);
  buttons->addWidget(render_button_);
  buttons->addWidget(cancel_button_);
  form->addRow(buttons);
  progress_ = new QProgressBar(render_box);
  progress_->setObjectName("progress");
  progress_->setRange(0, 1);
  progress_->setValue(0);
  progress_->setTextVisible(false);
  progress_->setFormat("%v / %m");
  form->addRow(progress_);
  progress_label_ = new QLabel(render_box);
  progress_label_->setObjectName("progress_label");
  form->addRow(progress_label_);
  layout->addWidget(render_box);

  OnMethodChanged();
  path_panel_ = new PathPanel(this, panel);
  layout->addWidget(path_panel_, 1);
  return panel;
}

QString MainWindow::ChooseFile(FileRole role, const QString& suggestion) {
  if (file_chooser_) return file_chooser_(role, suggestion);
  switch (role) {
    case FileRole::kOpenWorkspace:
      return QFileDialog::getExistingDirectory(this, "Open workspace", suggestion);
    case FileRole::kRenderFolder:
      return QFileDialog::getExistingDirectory(this, "Render path into folder",
                                               suggestion);
    case FileRole::kOpenWeights:
      return QFileDialog::getOpenFileName(this, "Network weights", suggestion,
                                          "Weights (*.safetensors);;All files (*)");
    case FileRole::kOpenPath:
      return QFileDialog::getOpenFileName(this, "Load camera path", suggestion,
                                          "nerfstudio camera path (*.json)");
    case FileRole::kSavePath:
      return QFileDialog::getSaveFileName(this, "Save camera path", suggestion,
                                          "nerfstudio camera path (*.json)");
  }
  return QString();
}

void MainWindow::ShowError(const QString& text) {
  message_is_error_ = true;
  message_->setText(text);
  message_->setStyleSheet(
      "QLabel { background: #5c1f1f; color: #ffdede; padding: 6px; border-radius: 3px; "
      "}");
  message_->show();
}

void MainWindow::ShowNote(const QString& text) {
  message_is_error_ = false;
  message_->setText(text);
  message_->setStyleSheet(
      "QLabel { background: #2d3238; color: #e0e0e0; padding: 6px; border-radius: 3px; "
      "}");
  message_->show();
}

void MainWindow::ClearMessage() {
  message_is_error_ = false;
  message_->clear();
  message_->hide();
}

QString MainWindow::message() const { return message_->text(); }

bool MainWindow::busy() const { return runner_->busy(); }

QString MainWindow::OpenWorkspace(const QString& path) {
  if (runner_->busy()) return "Busy: " + runner_->label() + " (Cancel it first)";
  const std::string workspace = path.toStdString();
  // The work runs on the task's thread and touches nothing of the window; the
  // continuation it returns runs on the GUI thread.
  runner_->Start(
      "Opening " + path,
      [this, workspace](const TaskRunner::Control&, const TaskRunner::ProgressFn&) {
        auto contents =
            std::make_shared<const WorkspaceContents>(LoadWorkspace(workspace));
        return TaskRunner::Continuation([this, contents] { ShowContents(contents); });
      },
      [this](const QString& error) { ShowError("Cannot open the workspace: " + error); });
  return QString();
}

void MainWindow::ShowContents(std::shared_ptr<const WorkspaceContents> contents) {
  contents_ = std::move(contents);
  last_render_.reset();
  ResetLiveRenderer();
  scene_view_->SetContents(contents_);
  path_panel_->SetContents(contents_);
  result_panel_->Show(nullptr, nullptr);
  int width = 640, height = 480;
  DefaultSize(*contents_, &width, &height);
  width_->setValue(width);
  height_->setValue(height);
  const QString summary = QString("%1\n%2 cameras, %3 sparse points, %4 mesh triangles")
                              .arg(QString::fromStdString(contents_->path))
                              .arg(contents_->num_views())
                              .arg(contents_->points.size())
                              .arg(contents_->mesh.faces.size());
  workspace_label_->setText(summary);
  statusBar()->showMessage(QString::fromStdString(contents_->path));
  // The GUI only reads: it opens a workspace that a prepare is still writing, and says
  // so, since what it shows is the workspace as it was when opened.
  const std::string holder = fvs::FolderLock::Holder(contents_->path);
  QString photos;
  try {
    const fvs::PhotoQualityReport quality =
        fvs::ReadPhotoQualityReport(fvs::PhotoQualityPath(contents_->path));
    if (quality.num_blurry() > 0 || quality.num_with_duplicates() > 0) {
      photos = " Photos: " + QString::fromStdString(quality.Summary()) + ".";
    }
  } catch (const fvs::Error& e) {
    photos = " " + QString::fromStdString(e.what()) + ".";
  }
  const QString notes =
      photos + (holder.empty()
                    ? QString()
                    : " Being written by " + QString::fromStdString(holder) +
                          ": reopen it when that has ended to see the result.");
  if (contents_->can_render()) {
    ShowNote("Opened " + QString::fromStdString(contents_->path) +
             ". Navigate (left drag orbit, right drag pan, wheel zoom, WASD fly, click a "
             "camera to look through it), then Render." +
             notes);
  } else {
    ShowError("Rendering is not available: " +
              QString::fromStdString(contents_->render_error) + notes);
  }
  UpdateEnabled();
  RequestLiveFrame();
}

void MainWindow::SetInitialSettings(const QString& method, const QString& model_path) {
  model_path_->setText(model_path);
  const int index = method_->findText(method);
  if (index >= 0) {
    method_->setCurrentIndex(index);
  } else {
    QStringList known;
    for (int i = 0; i < method_->count(); ++i) known << method_->itemText(i);
    ShowError("Unknown method '" + method + "' (known: " + known.join(", ") + ")");
  }
}

QString MainWindow::CannotRenderReason(const NovelViewOptions& request) const {
  if (!contents_) return "No workspace is open: File > Open workspace first.";
  if (!contents_->can_render()) {
    return "Rendering is not available: " +
           QString::fromStdString(contents_->render_error);
  }
  if (MethodNeedsWeights(request.method) && request.model_path.empty() &&
      DefaultModelPath(request.method, request.scene_model_dir).empty()) {
    return QString::fromStdString(request.method) +
           " needs network weights: choose a .safetensors file under Weights (no shipped "
           "or fine-tuned ones for this method; ulr and nearest need none).";
  }
  try {
    request.Check();
  } catch (const std::exception& e) {
    return QString("Cannot render: ") + e.what();
  }
  return QString();
}

NovelViewOptions MainWindow::CurrentRequest() const {
  NovelViewOptions request;
  request.method = method_->currentText().toStdString();
  request.num_sources = num_sources_->value();
  request.width = width_->value();
  request.height = height_->value();
  request.model_path = model_path_->text().trimmed().toStdString();
  if (contents_ && MethodNeedsWeights(request.method)) {
    request.feature_cache_dir = WorkspaceFeatureCacheDir(contents_->path);
    request.scene_model_dir = WorkspaceFinetunedModelDir(contents_->path);
  }
  return request;
}

PinholeCamera MainWindow::CurrentTargetCamera() const {
  const NovelViewOptions request = CurrentRequest();
  return TargetCameraFor(scene_view_->ViewCamera(), request.width, request.height);
}

void MainWindow::RenderCurrentView() {
  if (runner_->busy()) {
    ShowError("Busy: " + runner_->label() + " (wait for it or Cancel it)");
    return;
  }
  const NovelViewOptions request = CurrentRequest();
  const QString reason = CannotRenderReason(request);
  if (!reason.isEmpty()) {
    ShowError(reason);
    return;
  }
  const PinholeCamera camera = CurrentTargetCamera();
  std::shared_ptr<const Scene> scene = contents_->scene;
  std::shared_ptr<const WorkspaceContents> contents = contents_;
  runner_->Start(
      QString("Rendering %1 at %2x%3")
          .arg(QString::fromStdString(request.method))
          .arg(request.width)
          .arg(request.height),
      [this, scene, contents, camera, request](const TaskRunner::Control& control,
                                               const TaskRunner::ProgressFn&) {
        // Cancel stops the render within a row of work (util/cancel.h); the Cancelled
        // it throws ends the task, whose result the runner drops.
        const CancelScope scope(&control.cancelled);
        auto view = std::make_shared<const RenderedView>(
            RenderNovelView(*scene, camera, request));
        return TaskRunner::Continuation([this, view, contents] {
          if (contents != contents_) return;  // another workspace was opened meanwhile
          last_render_ = view;
          ClearMessage();
          result_panel_->Show(last_render_, contents_);
        });
      },
      [this](const QString& error) { ShowError("Render failed: " + error); });
}

void MainWindow::CancelTask() {
  if (!runner_->busy()) return;
  ShowNote("Cancelled: " + runner_->label() +
           (runner_->label().startsWith("Rendering")
                ? " (the render stops and its result is dropped)"
                : ""));
  runner_->Cancel();
}

void MainWindow::OnMethodChanged() {
  const bool needs = MethodNeedsWeights(method_->currentText().toStdString());
  model_path_->setEnabled(needs);
  RequestLiveFrame();
}

void MainWindow::SetLiveView(bool on) {
  if (live_action_->isChecked() != on)
    return live_action_->setChecked(on);  // toggles back
  scene_view_->SetLiveEnabled(on);
  if (!on && live_) live_->Pause();
  if (on) RequestLiveFrame();
}

bool MainWindow::live_view() const { return live_action_ && live_action_->isChecked(); }

double MainWindow::live_fps() const {
  // Frames over the span they arrived in, within the last second (a drag that began a
  // moment ago has had less than a second of frames).
  const double now = SteadySeconds();
  double first = now;
  int n = 0;
  for (double t : live_arrivals_) {
    if (now - t > 1.0) continue;
    first = std::min(first, t);
    ++n;
  }
  const double span = now - first;
  return n >= 2 && span > 0 ? (n - 1) / span : 0.0;
}

void MainWindow::ResetLiveRenderer() {
  live_.reset();  // joins its thread; what it posted is dropped by the epoch
  ++live_epoch_;
  live_frame_.reset();
  live_arrivals_.clear();
  if (!contents_ || !contents_->can_render()) return;
  const uint64_t epoch = live_epoch_;
  live_ = std::make_unique<LiveRenderer>(
      contents_->scene, LiveViewOptions(),
      [this, epoch](std::shared_ptr<const LiveFrame> frame) {
        QMetaObject::invokeMethod(
            this,
            [this, epoch, frame] {
              if (epoch == live_epoch_) ShowLiveFrame(frame);
            },
            Qt::QueuedConnection);
      },
      [this, epoch](const std::string& error) {
        const QString text = QString::fromStdString(error);
        QMetaObject::invokeMethod(
            this,
            [this, epoch, text] {
              if (epoch == live_epoch_) ShowError("Live view: " + text);
            },
            Qt::QueuedConnection);
      });
}

void MainWindow::RequestLiveFrame() {
  if (!live_ || !live_view() || runner_->busy()) return;
  NovelViewOptions request = CurrentRequest();
  // The live frames need no weights; the complete frame falls back to ulr when the
  // chosen method cannot render (Render says why).
  if (!CannotRenderReason(request).isEmpty()) {
    request = NovelViewOptions();
    request.method = "ulr";
  }
  live_->Request(scene_view_->ViewCamera(), request);
}

void MainWindow::ShowLiveFrame(std::shared_ptr<const LiveFrame> frame) {
  live_frame_ = frame;
  const RenderedView& view = frame->view;
  const Image& color = view.result.color;
  const QString size = QString("%1x%2").arg(color.width).arg(color.height);
  const QString method = QString::fromStdString(view.method);
  QString caption;
  if (frame->level == 0 && !frame->complete()) {
    live_arrivals_.push_back(SteadySeconds());
    while (live_arrivals_.size() > 64) live_arrivals_.pop_front();
    caption =
        QString("Live: %1 at %2, %3 fps").arg(method, size).arg(live_fps(), 0, 'f', 0);
  } else if (!frame->complete()) {
    caption = QString("Sharpening %1/%2: %3 at %4")
                  .arg(frame->level + 1)
                  .arg(frame->num_levels)
                  .arg(method, size);
  } else {
    caption = QString("%1 at %2, K %3, %4 s")
                  .arg(method, size)
                  .arg(view.num_sources > 0 ? QString::number(view.num_sources) : "auto")
                  .arg(view.seconds, 0, 'f', 2);
  }
  scene_view_->SetLiveImage(ToQImage(color), caption);
}

void MainWindow::UpdateEnabled() {
  const bool busy = runner_->busy();
  const bool can_render = contents_ && contents_->can_render();
  // Enabled without a mesh too: clicking says why nothing can be rendered.
  render_button_->setEnabled(!busy && contents_ != nullptr);
  render_action_->setEnabled(!busy && contents_ != nullptr);
  cancel_button_->setEnabled(busy);
  cancel_action_->setEnabled(busy);
  path_panel_->UpdateEnabled(busy, can_render);
}

}  // namespace fvs::ui
