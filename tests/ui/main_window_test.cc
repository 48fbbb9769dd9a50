// The application used as a person would: a real window under Xvfb (Mesa's software
// OpenGL), a generated scene opened through the File menu, the 3D view checked on its
// pixels, views rendered with the Render button, errors shown in the window, and a camera
// path built, saved, loaded back and rendered to frames.
#include "ui/main_window.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QMouseEvent>
#include <QPainter>
#include <QProgressBar>
#include <QPushButton>
#include <QRadioButton>
#include <QSpinBox>
#include <QTest>
#include <cmath>
#include <filesystem>
#include <functional>

#include "colmap_ext/image_io.h"
#include "fvs/path/camera_path.h"
#include "fvs/path/video.h"
#include "fvs/scene/photo_quality.h"
#include "fvs/util/folder_lock.h"
#include "support/test_support.h"
#include "ui/image_view.h"
#include "ui/live_view.h"
#include "ui/path_panel.h"
#include "ui/scene_view.h"
#include "ui/ui_test_scene.h"

namespace fvs::ui {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

// Processes events until `done` or `timeout_ms` has passed.
bool WaitFor(const std::function<bool()>& done, int timeout_ms = 60000) {
  QElapsedTimer timer;
  timer.start();
  while (!done()) {
    if (timer.elapsed() > timeout_ms) return false;
    QTest::qWait(10);
  }
  return true;
}

// Fraction of pixels that differ from the first pixel's colour, and the number of
// differing pixels between two images of one size.
double NonBackgroundFraction(const QImage& image) {
  const QImage rgb = image.convertToFormat(QImage::Format_RGB32);
  const QRgb background = rgb.pixel(0, 0);
  int64_t other = 0;
  for (int y = 0; y < rgb.height(); ++y) {
    for (int x = 0; x < rgb.width(); ++x) other += rgb.pixel(x, y) != background;
  }
  return static_cast<double>(other) / std::max(1, rgb.width() * rgb.height());
}

int64_t DifferingPixels(const QImage& a, const QImage& b) {
  const QImage x = a.convertToFormat(QImage::Format_RGB32);
  const QImage y = b.convertToFormat(QImage::Format_RGB32);
  if (x.size() != y.size()) return x.width() * x.height();
  int64_t n = 0;
  for (int r = 0; r < x.height(); ++r) {
    for (int c = 0; c < x.width(); ++c) n += x.pixel(c, r) != y.pixel(c, r);
  }
  return n;
}

template <typename T>
T* Find(QWidget* window, const char* name) {
  T* widget = window->findChild<T*>(name);
  EXPECT_NE(widget, nullptr) << name;
  return widget;
}

class MainWindowTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SetDefaultSurfaceFormat();
    static int argc = 1;
    static char name[] = "main_window_test";
    static char* argv[] = {name, nullptr};
    app_ = new QApplication(argc, argv);
    workspace_ = new TempDir();
    GenerateUiTestScene(workspace_->path(), 7, 160, 120);
  }
  static void TearDownTestSuite() {
    delete workspace_;
    delete app_;
  }

  void SetUp() override {
    window_ = std::make_unique<MainWindow>();
    window_->SetFileChooser([this](FileRole role, const QString&) {
      const QString answer = answers_[static_cast<int>(role)];
      return answer;
    });
    // The tests of the 3D view's drawing and of Render see the scene itself; the live
    // view (on by default) has tests of its own below.
    window_->SetLiveView(false);
    window_->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(window_.get()));
  }
  void TearDown() override { window_.reset(); }

  void Answer(FileRole role, const std::string& path) {
    answers_[static_cast<int>(role)] = QString::fromStdString(path);
  }
  QAction* Action(const char* name) {
    QAction* action = window_->findChild<QAction*>(name);
    EXPECT_NE(action, nullptr) << name;
    return action;
  }
  void Click(const char* button) {
    QPushButton* b = Find<QPushButton>(window_.get(), button);
    ASSERT_TRUE(b->isEnabled()) << button;
    QTest::mouseClick(b, Qt::LeftButton);
  }
  bool WaitIdle(int timeout_ms = 60000) {
    return WaitFor([this] { return !window_->busy(); }, timeout_ms);
  }
  // Opens the generated workspace through File > Open workspace.
  void OpenWorkspace(const std::string& path) {
    Answer(FileRole::kOpenWorkspace, path);
    Action("action_open")->trigger();
    ASSERT_TRUE(WaitIdle());
  }

  static QApplication* app_;
  static TempDir* workspace_;
  std::unique_ptr<MainWindow> window_;
  QString answers_[5];
};

QApplication* MainWindowTest::app_ = nullptr;
TempDir* MainWindowTest::workspace_ = nullptr;

TEST_F(MainWindowTest, OpensTheSceneShowsItAndRendersTheViewpoint) {
  OpenWorkspace(workspace_->path());
  ASSERT_NE(window_->contents(), nullptr) << window_->message().toStdString();
  EXPECT_FALSE(window_->message_is_error()) << window_->message().toStdString();
  EXPECT_TRUE(window_->contents()->can_render());
  EXPECT_EQ(window_->contents()->num_views(), 8);
  EXPECT_GT(window_->contents()->points.size(), 100u);
  EXPECT_GT(window_->contents()->mesh.faces.size(), 100u);

  // The 3D view shows the scene: the mesh fills the view from a registered camera; with
  // the mesh hidden only points and frusta remain, on the background.
  SceneView* view = window_->scene_view();
  const QImage with_mesh = view->grabFramebuffer();
  EXPECT_GT(NonBackgroundFraction(with_mesh), 0.9);
  Action("action_show_mesh")->trigger();
  Action("action_overview")->trigger();
  const QImage without_mesh = view->grabFramebuffer();
  const double sparse_fraction = NonBackgroundFraction(without_mesh);
  EXPECT_GT(sparse_fraction, 0.002);
  EXPECT_LT(sparse_fraction, 0.5);
  Action("action_show_mesh")->trigger();
  Action("action_reset_view")->trigger();

  // Navigation: dragging orbits, the wheel zooms; both change the picture.
  const Eigen::Vector3d focus = view->camera().focus();
  QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, QPoint(200, 200));
  QMouseEvent move(QEvent::MouseMove, QPoint(260, 210), Qt::LeftButton, Qt::LeftButton,
                   Qt::NoModifier);
  QApplication::sendEvent(view, &move);
  QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, QPoint(260, 210));
  EXPECT_LT((view->camera().focus() - focus).norm(), 1e-9);
  EXPECT_GT(DifferingPixels(view->grabFramebuffer(), with_mesh), 1000);
  const Eigen::Vector3d centre = view->camera().center();
  QTest::keyClick(view, Qt::Key_W);  // fly forward
  EXPECT_GT((view->camera().center() - centre).dot(view->camera().rotation().row(2)), 0);

  // A click on a registered camera looks through it (seen from behind and above it).
  const PinholeCamera target = window_->contents()->cameras[3];
  const double scale = window_->contents()->scale;
  view->camera().LookAt(target.Center() - scale * target.ViewDirection() +
                            0.3 * scale * window_->contents()->up,
                        target.Center(), window_->contents()->up);
  const PinholeCamera current = view->ViewCamera();
  const Eigen::Vector3d xc = current.WorldToCamera(target.Center());
  ASSERT_GT(xc.z(), 0);
  const Eigen::Vector2d pixel = current.CameraToPixel(xc);
  QTest::mouseClick(view, Qt::LeftButton, Qt::NoModifier,
                    QPoint(static_cast<int>(pixel.x()), static_cast<int>(pixel.y())));
  EXPECT_LT((view->camera().center() - target.Center()).norm(), 1e-9);
  EXPECT_LT((view->camera().rotation() - target.R).norm(), 1e-9);

  // Render at that camera with the Render button: progress shows while it runs, the
  // window stays responsive, and the view equals the photo taken there.
  const QImage before = window_->grab().toImage();
  Find<QComboBox>(window_.get(), "method")->setCurrentText("ulr");
  Click("render_button");
  EXPECT_TRUE(window_->busy());
  EXPECT_EQ(Find<QProgressBar>(window_.get(), "progress")->maximum(), 0);  // busy bar
  EXPECT_TRUE(Find<QPushButton>(window_.get(), "cancel_button")->isEnabled());
  ASSERT_TRUE(WaitIdle());
  ASSERT_TRUE(window_->last_render() != nullptr) << window_->message().toStdString();
  const RenderedView& rendered = *window_->last_render();
  ASSERT_EQ(rendered.result.color.width, 160);
  ASSERT_EQ(rendered.result.color.height, 120);
  EXPECT_EQ(rendered.nearest_view,
            window_->contents()->scene->FindView(window_->contents()->view_names[3]));
  double error = 0;
  const Image& photo = rendered.nearest_photo;
  for (size_t i = 0; i < photo.data.size(); ++i) {
    error += std::abs(photo.data[i] - rendered.result.color.data[i]);
  }
  EXPECT_LT(error / photo.data.size(), 0.03);

  auto* result_view = Find<ImageView>(window_.get(), "result_view");
  auto* source_view = Find<ImageView>(window_.get(), "source_view");
  EXPECT_EQ(result_view->image().size(), QSize(160, 120));
  EXPECT_EQ(source_view->image().size(), QSize(160, 120));
  EXPECT_TRUE(source_view->caption().contains("frame_0003"))
      << source_view->caption().toStdString();
  const QString info = Find<QLabel>(window_.get(), "render_info")->text();
  EXPECT_TRUE(info.contains("ulr") && info.contains(" s ") &&
              info.contains("Sources used"))
      << info.toStdString();
  const QImage after = window_->grab().toImage();
  EXPECT_GT(DifferingPixels(before, after), 2 * 160 * 120 / 4);

  // Layers: target depth and confidence replace the colour image.
  const QImage colour = result_view->image();
  QTest::mouseClick(Find<QRadioButton>(window_.get(), "layer_depth"), Qt::LeftButton);
  EXPECT_GT(DifferingPixels(colour, result_view->image()), 160 * 120 / 2);
  EXPECT_TRUE(result_view->caption().contains("depth"));
  QTest::mouseClick(Find<QRadioButton>(window_.get(), "layer_confidence"),
                    Qt::LeftButton);
  EXPECT_TRUE(result_view->caption().contains("Confidence"));
  QTest::mouseClick(Find<QRadioButton>(window_.get(), "layer_color"), Qt::LeftButton);
  EXPECT_EQ(DifferingPixels(colour, result_view->image()), 0);
}

TEST_F(MainWindowTest, ErrorsShowInTheWindowWhichStaysUsable) {
  // A folder that does not exist, then one without a sparse model.
  OpenWorkspace(workspace_->path() + "/no_such_folder");
  EXPECT_TRUE(window_->message_is_error());
  EXPECT_TRUE(window_->message().contains("no_such_folder"))
      << window_->message().toStdString();
  EXPECT_EQ(window_->contents(), nullptr);
  TempDir empty;
  OpenWorkspace(empty.path());
  EXPECT_TRUE(window_->message().contains("sparse")) << window_->message().toStdString();

  // A COLMAP workspace without a proxy mesh opens (points, cameras) but cannot render.
  TempDir no_mesh;
  fs::copy(workspace_->path() + "/sparse", no_mesh / "sparse");
  fs::copy(workspace_->path() + "/images", no_mesh / "images");
  OpenWorkspace(no_mesh.path());
  ASSERT_NE(window_->contents(), nullptr);
  EXPECT_FALSE(window_->contents()->can_render());
  EXPECT_EQ(window_->contents()->num_views(), 8);
  EXPECT_TRUE(window_->message_is_error());
  EXPECT_TRUE(window_->message().contains("meshed-delaunay.ply"));
  Click("render_button");
  EXPECT_FALSE(window_->busy());
  EXPECT_TRUE(window_->message().contains("meshed-delaunay.ply"));
  EXPECT_GT(NonBackgroundFraction(window_->scene_view()->grabFramebuffer()), 0.002);

  // The network without weights, then with a file that is not weights.
  OpenWorkspace(workspace_->path());
  ASSERT_TRUE(window_->contents()->can_render());
  auto* method = Find<QComboBox>(window_.get(), "method");
  ASSERT_GE(method->findText("fvs_fast"), 0);
  method->setCurrentText("fvs_fast");
  Click("render_button");
  EXPECT_TRUE(window_->message_is_error());
  EXPECT_TRUE(window_->message().contains("weights")) << window_->message().toStdString();
  const std::string bogus = empty / "weights.safetensors";
  testing::WriteTextFile(bogus, "not a safetensors file");
  Find<QLineEdit>(window_.get(), "model_path")->setText(QString::fromStdString(bogus));
  Click("render_button");
  ASSERT_TRUE(WaitIdle());
  EXPECT_TRUE(window_->message_is_error());
  EXPECT_TRUE(window_->message().contains("Render failed") &&
              window_->message().contains("weights.safetensors"))
      << window_->message().toStdString();
  EXPECT_EQ(window_->last_render(), nullptr);

  // Still usable: ulr renders.
  method->setCurrentText("ulr");
  Click("render_button");
  ASSERT_TRUE(WaitIdle());
  EXPECT_TRUE(window_->last_render() != nullptr) << window_->message().toStdString();
  EXPECT_FALSE(window_->message_is_error());
}

// Issue 42: the GUI only reads, so it opens a workspace another process is writing and
// names the writer; and it repeats prepare's line on blurry and duplicate photos.
TEST_F(MainWindowTest, NamesAWriterOfTheWorkspaceAndTheBlurryPhotos) {
  TempDir copy;
  ASSERT_EQ(
      testing::RunShell("cp -a '" + workspace_->path() + "'/. '" + copy.path() + "'/"),
      0);
  PhotoQualityReport quality;
  quality.median_sharpness = 0.01;
  quality.photos.push_back({"frame_0003.png", 0.001, 0.1, true, {}});
  WritePhotoQualityReport(PhotoQualityPath(copy.path()), quality);
  const FolderLock writer(copy.path(), "view_synthesis_prepare");
  OpenWorkspace(copy.path());
  ASSERT_NE(window_->contents(), nullptr) << window_->message().toStdString();
  const std::string message = window_->message().toStdString();
  EXPECT_NE(message.find("1 of 1 photos blurry: frame_0003.png (10 % of the median)"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("Being written by colmap view_synthesis_prepare (process " +
                         std::to_string(::getpid())),
            std::string::npos)
      << message;
}

TEST_F(MainWindowTest, CameraPathIsBuiltSavedLoadedAndRendered) {
  OpenWorkspace(workspace_->path());
  ASSERT_NE(window_->contents(), nullptr);
  PathPanel* panel = window_->path_panel();
  SceneView* view = window_->scene_view();
  Find<QSpinBox>(window_.get(), "fps")->setValue(4);
  Find<QDoubleSpinBox>(window_.get(), "seconds_per_keyframe")->setValue(1.0);

  for (int camera : {0, 5, 2}) {
    view->LookThroughCamera(camera);
    Click("add_keyframe_button");
  }
  ASSERT_EQ(panel->keyframes().size(), 3u);
  // The last keyframe (camera 2) moves up between 0 and 5; a fourth is added and deleted.
  auto* list = Find<QListWidget>(window_.get(), "keyframe_list");
  list->setCurrentRow(2);
  Click("move_keyframe_up_button");
  view->LookThroughCamera(7);
  Click("add_keyframe_button");
  ASSERT_EQ(panel->keyframes().size(), 4u);
  EXPECT_EQ(list->currentRow(), 2);  // inserted after the selected keyframe
  Click("delete_keyframe_button");
  ASSERT_EQ(panel->keyframes().size(), 3u);
  const auto& scene = *window_->contents()->scene;
  const int order[] = {0, 2, 5};
  for (int i = 0; i < 3; ++i) {
    const PinholeCamera world =
        scene.ToWorldCamera(window_->contents()->cameras[order[i]]);
    EXPECT_LT((panel->keyframes()[i].camera.Center() - world.Center()).norm(), 1e-6) << i;
  }

  // Preview: the path is computed, drawn and played in the 3D view.
  Click("preview_path_button");
  ASSERT_TRUE(WaitIdle());
  EXPECT_FALSE(window_->message_is_error()) << window_->message().toStdString();
  ASSERT_GE(panel->preview_frames().size(), 8u);
  EXPECT_TRUE(WaitFor([panel] { return !panel->previewing(); }, 20000));
  EXPECT_LT((view->camera().center() - panel->preview_frames().back().Center()).norm(),
            1e-9);

  // Save, read back with the path library, load into a fresh panel.
  TempDir out;
  const std::string path_file = out / "camera_path.json";
  Answer(FileRole::kSavePath, path_file);
  Click("save_path_button");
  ASSERT_TRUE(WaitIdle());
  ASSERT_TRUE(fs::exists(path_file)) << window_->message().toStdString();
  const std::vector<CameraPathKeyframe> saved = ReadNerfstudioKeyframes(path_file);
  ASSERT_EQ(saved.size(), 3u);
  EXPECT_EQ(ReadNerfstudioCameraPath(path_file).size(), panel->preview_frames().size());
  const std::vector<CameraPathKeyframe> before = panel->keyframes();
  OpenWorkspace(workspace_->path());  // clears the keyframes
  ASSERT_TRUE(window_->path_panel()->keyframes().empty());
  Answer(FileRole::kOpenPath, path_file);
  Action("action_load_path")->trigger();
  ASSERT_EQ(window_->path_panel()->keyframes().size(), 3u)
      << window_->message().toStdString();
  for (int i = 0; i < 3; ++i) {
    const PinholeCamera& a = before[i].camera;
    const PinholeCamera& b = window_->path_panel()->keyframes()[i].camera;
    EXPECT_LT((a.R - b.R).norm(), 1e-9);
    EXPECT_LT((a.Center() - b.Center()).norm(), 1e-9);
    EXPECT_NEAR(a.fy / a.height, b.fy / b.height, 1e-9);
  }
  Answer(FileRole::kOpenPath, out / "missing.json");
  Action("action_load_path")->trigger();
  EXPECT_TRUE(window_->message_is_error());
  EXPECT_TRUE(window_->message().contains("missing.json"));
  EXPECT_EQ(window_->path_panel()->keyframes().size(), 3u);

  // Render the path to frames with progress.
  Find<QSpinBox>(window_.get(), "width")->setValue(96);
  Find<QSpinBox>(window_.get(), "height")->setValue(72);
  const std::string frames_dir = out / "frames";
  Answer(FileRole::kRenderFolder, frames_dir);
  Click("render_path_button");
  EXPECT_TRUE(window_->busy());
  ASSERT_TRUE(WaitIdle());
  EXPECT_FALSE(window_->message_is_error()) << window_->message().toStdString();
  const size_t num_frames =
      ReadNerfstudioCameraPath(frames_dir + "/camera_path.json").size();
  ASSERT_GE(num_frames, 8u);
  for (size_t i = 0; i < num_frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/frame_%05zu.png", i);
    EXPECT_TRUE(fs::exists(frames_dir + name)) << name;
  }
  // The first frame is the first keyframe, camera 0: its render looks like that photo.
  const Image first = colmap::ReadImage(frames_dir + "/frame_00000.png");
  ASSERT_EQ(first.width, 96);
  const Image photo = colmap::ReadImage(workspace_->path() + "/images/" +
                                        window_->contents()->view_names[0]);
  double difference = 0;
  for (int y = 0; y < 72; ++y) {
    for (int x = 0; x < 96; ++x) {
      for (int c = 0; c < 3; ++c) {
        // Nearest pixel of the 160x120 photo (same field of view).
        difference +=
            std::abs(first.at(x, y, c) - photo.at(x * 160 / 96, y * 120 / 72, c));
      }
    }
  }
  EXPECT_LT(difference / (96 * 72 * 3), 0.1);
  if (FindFfmpeg().empty()) {
    EXPECT_TRUE(window_->message().contains("ffmpeg is not on the PATH"));
  } else {
    EXPECT_TRUE(fs::exists(frames_dir + "/path.mp4"));
  }

  // Cancel between frames: the window is free at once, and the rendering stops early.
  Find<QSpinBox>(window_.get(), "fps")->setValue(60);
  const std::string cancelled_dir = out / "cancelled";
  Answer(FileRole::kRenderFolder, cancelled_dir);
  Click("render_path_button");
  ASSERT_TRUE(WaitFor([&] { return fs::exists(cancelled_dir + "/frame_00000.png"); }));
  Click("cancel_button");
  EXPECT_FALSE(window_->busy());
  EXPECT_TRUE(window_->message().contains("Cancelled"));
  Click("add_keyframe_button");  // usable again
  EXPECT_EQ(window_->path_panel()->keyframes().size(), 4u);
}

// Mean absolute difference of neighbouring pixels (grey levels): an upsampled live
// frame has less of it than the sharpened one.
double Sharpness(const QImage& image) {
  const QImage grey = image.convertToFormat(QImage::Format_Grayscale8);
  double sum = 0;
  int64_t n = 0;
  for (int y = 0; y + 1 < grey.height(); ++y) {
    const uchar* row = grey.constScanLine(y);
    const uchar* below = grey.constScanLine(y + 1);
    for (int x = 0; x + 1 < grey.width(); ++x) {
      sum += std::abs(row[x + 1] - row[x]) + std::abs(below[x] - row[x]);
      n += 2;
    }
  }
  return sum / std::max<int64_t>(n, 1);
}

// Sends a left-button drag to the 3D view as a mouse would, one move every 30 ms.
void Drag(QWidget* view, QPoint from, QPoint to, int steps,
          const std::function<void(int)>& after_step) {
  QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, from);
  for (int i = 1; i <= steps; ++i) {
    const QPoint p = from + (to - from) * i / steps;
    QMouseEvent move(QEvent::MouseMove, p, view->mapToGlobal(p), Qt::NoButton,
                     Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(view, &move);
    QTest::qWait(30);
    if (after_step) after_step(i);
  }
  QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, to);
}

// The live view as a person uses it: open a workspace, drag the camera, see the view
// rendered from the photos follow the mouse at a reduced resolution, let go, see it
// sharpen to the full size; then Render is still the command line's.
TEST_F(MainWindowTest, LiveViewFollowsTheMouseAndSharpensWhenItStops) {
  // Photos larger than the live frames, so that sharpening shows.
  TempDir sharp;
  GenerateUiTestScene(sharp.path(), 5, 640, 480);
  window_->SetLiveView(true);
  OpenWorkspace(sharp.path());
  ASSERT_TRUE(window_->contents() && window_->contents()->can_render())
      << window_->message().toStdString();
  SceneView* view = window_->scene_view();
  const auto complete = [this] {
    return window_->live_frame() && window_->live_frame()->complete();
  };
  ASSERT_TRUE(WaitFor(complete));
  EXPECT_TRUE(view->showing_live_image());
  EXPECT_EQ(window_->live_frame()->view.camera.width, view->width());
  EXPECT_EQ(window_->live_frame()->view.camera.height, view->height());
  const QImage still = view->grabFramebuffer();
  const uint64_t first_pose = window_->live_frame()->pose_id;

  // Dragging: live frames of new poses, smaller than the view, the caption says so.
  QImage moving;
  int live_frames = 0;
  uint64_t last_live_pose = first_pose;
  const QPoint centre(view->width() / 2, view->height() / 2);
  Drag(view, centre, centre + QPoint(view->width() / 6, view->height() / 20), 20,
       [&](int) {
         const auto& frame = window_->live_frame();
         if (frame && frame->level == 0 && frame->pose_id != last_live_pose) {
           ++live_frames;
           last_live_pose = frame->pose_id;
           moving = view->grabFramebuffer();
           EXPECT_LT(frame->view.camera.width, view->width());
           EXPECT_TRUE(view->live_caption().startsWith("Live: ulr at"))
               << view->live_caption().toStdString();
         }
       });
  std::printf("live frames while dragging 20 moves of 30 ms: %d, %.0f fps at the end\n",
              live_frames, window_->live_fps());
  EXPECT_GE(live_frames, 2);
  ASSERT_FALSE(moving.isNull());
  EXPECT_GT(DifferingPixels(moving, still), moving.width() * moving.height() / 10)
      << "the live view did not change with the camera";

  // Stopped: it sharpens to the full size, the last frame the chosen method's.
  ASSERT_TRUE(WaitFor(complete));
  EXPECT_GT(window_->live_frame()->pose_id, first_pose);
  const QImage sharpened = view->grabFramebuffer();
  EXPECT_TRUE(view->live_caption().startsWith("ulr at"))
      << view->live_caption().toStdString();
  std::printf("sharpness (mean neighbour difference): moving %.2f, sharpened %.2f\n",
              Sharpness(moving), Sharpness(sharpened));
  EXPECT_GT(Sharpness(sharpened), 1.08 * Sharpness(moving));

  // Switched off, the 3D view shows the scene again; switched on, the view again.
  Action("action_live_view")->trigger();
  EXPECT_FALSE(window_->live_view());
  EXPECT_FALSE(view->showing_live_image());
  Action("action_live_view")->trigger();
  EXPECT_TRUE(view->showing_live_image());

  // Render pauses the live view and gives the command line's render of the chosen size.
  Click("render_button");
  ASSERT_TRUE(WaitIdle());
  ASSERT_NE(window_->last_render(), nullptr) << window_->message().toStdString();
  EXPECT_FALSE(window_->message_is_error()) << window_->message().toStdString();
}

}  // namespace
}  // namespace fvs::ui

namespace fvs::ui {
namespace {

// Not a check: with FVS_UI_SCREENSHOT_DIR set, saves the screenshots of doc/gui.md
// (of FVS_UI_SCREENSHOT_WORKSPACE, e.g. the demo's prepared workspace, else the generated
// scene). Skipped otherwise.
TEST_F(MainWindowTest, Screenshots) {
  const char* dir = std::getenv("FVS_UI_SCREENSHOT_DIR");
  if (dir == nullptr) GTEST_SKIP() << "FVS_UI_SCREENSHOT_DIR not set";
  const char* workspace = std::getenv("FVS_UI_SCREENSHOT_WORKSPACE");
  OpenWorkspace(workspace ? workspace : workspace_->path());
  ASSERT_NE(window_->contents(), nullptr) << window_->message().toStdString();
  window_->resize(1180, 800);
  QTest::qWait(200);
  const WorkspaceContents& w = *window_->contents();
  SceneView* view = window_->scene_view();

  // Overview from above the cameras, mesh hidden: sparse points and frusta.
  Action("action_show_mesh")->trigger();
  Action("action_overview")->trigger();
  QTest::qWait(200);
  // Highest PNG compression: the pages keep each picture under ~300 KB.
  ASSERT_TRUE(
      window_->grab().toImage().save(QString(dir) + "/gui_3d_view.png", "PNG", 0));

  // A novel viewpoint between two cameras, rendered with ulr, beside its nearest photo
  // (points hidden: on the mesh they add noise that PNG compresses badly).
  Action("action_show_mesh")->trigger();
  Action("action_show_points")->trigger();
  view->LookThroughCamera(2);
  view->camera().Orbit(0.12, 0.05, w.up);
  view->camera().Fly({0.05 * w.scale, 0, 0.1 * w.scale});
  Find<QComboBox>(window_.get(), "method")->setCurrentText("ulr");
  Click("render_button");
  ASSERT_TRUE(WaitIdle());
  ASSERT_TRUE(window_->last_render() != nullptr) << window_->message().toStdString();
  QTest::qWait(200);
  // At 70 % of its size the picture stays readable and under ~300 KB.
  const QImage shot = window_->grab().toImage();
  ASSERT_TRUE(shot.scaledToWidth(shot.width() * 70 / 100, Qt::SmoothTransformation)
                  .save(QString(dir) + "/gui_render.png", "PNG", 0));

  // A camera path through three registered cameras, previewed, seen from above.
  Find<QSpinBox>(window_.get(), "fps")->setValue(10);
  const int n = w.num_views();
  for (int camera : {0, n / 2, n - 1}) {
    view->LookThroughCamera(camera);
    Click("add_keyframe_button");
  }
  Click("preview_path_button");
  ASSERT_TRUE(WaitIdle());
  ASSERT_TRUE(WaitFor([this] { return !window_->path_panel()->previewing(); }));
  Action("action_show_mesh")->trigger();
  Action("action_show_points")->trigger();
  Action("action_overview")->trigger();
  QTest::qWait(200);
  const QImage path_shot = window_->grab().toImage();
  ASSERT_TRUE(
      path_shot.scaledToWidth(path_shot.width() * 75 / 100, Qt::SmoothTransformation)
          .save(QString(dir) + "/gui_path.png", "PNG", 0));
}

// The window with the 3D view's own frame drawn in (QWidget::grab shows the OpenGL
// widget's clear colour only when the frame is drawn with QPainter).
QImage GrabWithLiveView(QWidget* window, SceneView* view) {
  QImage shot = window->grab().toImage();
  QPainter painter(&shot);
  painter.drawImage(view->mapTo(window, QPoint(0, 0)), view->grabFramebuffer());
  return shot;
}

// Not a check either: the live view's screenshots of doc/gui.md (the window while
// dragging, and after it sharpened), of FVS_UI_SCREENSHOT_WORKSPACE. Skipped otherwise.
TEST_F(MainWindowTest, LiveScreenshots) {
  const char* dir = std::getenv("FVS_UI_SCREENSHOT_DIR");
  const char* workspace = std::getenv("FVS_UI_SCREENSHOT_WORKSPACE");
  if (dir == nullptr || workspace == nullptr) {
    GTEST_SKIP() << "FVS_UI_SCREENSHOT_DIR or FVS_UI_SCREENSHOT_WORKSPACE not set";
  }
  window_->SetLiveView(true);
  OpenWorkspace(workspace);
  ASSERT_TRUE(window_->contents() && window_->contents()->can_render());
  window_->resize(1180, 800);
  const auto complete = [this] {
    return window_->live_frame() && window_->live_frame()->complete();
  };
  ASSERT_TRUE(WaitFor(complete));
  SceneView* view = window_->scene_view();
  QImage moving;
  const QPoint centre(view->width() / 2, view->height() / 2);
  Drag(view, centre, centre + QPoint(view->width() / 8, 0), 40, [&](int step) {
    if (step > 30 && window_->live_frame() && window_->live_frame()->level == 0)
      moving = GrabWithLiveView(window_.get(), view);
  });
  ASSERT_FALSE(moving.isNull());
  ASSERT_TRUE(WaitFor(complete));
  QTest::qWait(100);
  const QImage sharp = GrabWithLiveView(window_.get(), view);
  for (const auto& [image, name] : {std::pair{moving, "gui_live_moving.png"},
                                    std::pair{sharp, "gui_live_sharp.png"}}) {
    ASSERT_TRUE(image.scaledToWidth(image.width() * 70 / 100, Qt::SmoothTransformation)
                    .save(QString(dir) + "/" + name, "PNG", 0));
  }
}

}  // namespace
}  // namespace fvs::ui
