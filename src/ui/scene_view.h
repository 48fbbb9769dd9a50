// The 3D view: sparse points, registered cameras as frusta and the proxy mesh (each can
// be hidden), drawn with OpenGL 3.3 core (Mesa's llvmpipe has it under Xvfb). Navigation
// as in COLMAP's viewer: left drag orbits, right (or middle, or shift+left) drag pans,
// the wheel zooms, W/A/S/D fly forward/left/back/right and Q/E down/up; a click on a
// camera looks through it. Keyframes and a previewed path are drawn as extra
// frusta/lines.
#pragma once

#include <QImage>
#include <QOpenGLBuffer>
#include <QOpenGLExtraFunctions>
#include <QOpenGLShaderProgram>
#include <QOpenGLVertexArrayObject>
#include <QOpenGLWidget>
#include <QPoint>
#include <QString>
#include <memory>
#include <vector>

#include "ui/viewer_camera.h"
#include "ui/workspace_contents.h"

namespace fvs::ui {

class SceneView : public QOpenGLWidget, protected QOpenGLExtraFunctions {
  Q_OBJECT

 public:
  explicit SceneView(QWidget* parent = nullptr);
  ~SceneView() override;

  // Shows a workspace (kept alive by the caller while shown) and frames it.
  void SetContents(std::shared_ptr<const WorkspaceContents> contents);
  void ResetView();
  // An oblique view from above onto the middle of the sparse points (all of the scene).
  void ShowOverview();
  void LookThroughCamera(int index);

  void SetShowPoints(bool show);
  void SetShowCameras(bool show);
  void SetShowMesh(bool show);
  // Cameras to highlight (the sources of the last render), by index into the contents.
  void SetHighlighted(std::vector<int> indices);
  // Extra frusta (keyframes) and a polyline of camera centres (a previewed path), scene
  // frame.
  void SetKeyframes(std::vector<PinholeCamera> cameras);
  void SetPathPreview(std::vector<Eigen::Vector3d> centers);

  // The live novel view (ui/live_view.h, driven by the window): while on and a frame has
  // arrived, the view shows that frame (scaled to the widget) with its caption instead
  // of the points, cameras and mesh.
  void SetLiveEnabled(bool on);
  bool live_enabled() const { return live_enabled_; }
  void SetLiveImage(QImage image, const QString& caption);
  void ClearLiveImage();
  bool showing_live_image() const { return live_enabled_ && !live_image_.isNull(); }
  const QString& live_caption() const { return live_caption_; }

  ViewerCamera& camera() { return camera_; }
  const ViewerCamera& camera() const { return camera_; }
  // The view as a pinhole camera of the widget's size (scene frame).
  PinholeCamera ViewCamera() const;

 Q_SIGNALS:
  void cameraClicked(int index);
  void viewChanged();

 protected:
  void initializeGL() override;
  void resizeGL(int width, int height) override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;

 private:
  struct Batch {  // one vertex array: positions + colours, optionally indexed
    QOpenGLVertexArrayObject vao;
    QOpenGLBuffer vertices{QOpenGLBuffer::VertexBuffer};
    QOpenGLBuffer indices{QOpenGLBuffer::IndexBuffer};
    int count = 0;
  };
  void Upload(Batch* batch, const std::vector<float>& interleaved,
              const std::vector<unsigned int>& indices);
  void UploadScene();
  void UploadOverlays();
  void Draw(QOpenGLShaderProgram* program, Batch* batch, unsigned int mode,
            const Eigen::Matrix4d& mvp, bool indexed);
  void PaintLiveImage();

  std::shared_ptr<const WorkspaceContents> contents_;
  ViewerCamera camera_;
  bool show_points_ = true, show_cameras_ = true, show_mesh_ = true;
  std::vector<int> highlighted_;
  std::vector<PinholeCamera> keyframes_;
  std::vector<Eigen::Vector3d> path_preview_;
  bool live_enabled_ = false;
  QImage live_image_;
  QString live_caption_;

  bool gl_ready_ = false, scene_dirty_ = true, overlays_dirty_ = true;
  std::unique_ptr<QOpenGLShaderProgram> flat_program_, mesh_program_;
  Batch points_, cameras_, mesh_, overlays_;

  QPoint press_position_, last_position_;
  bool dragged_ = false;
};

}  // namespace fvs::ui
