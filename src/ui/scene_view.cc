#include "ui/scene_view.h"

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>

namespace fvs::ui {
namespace {

// Positions and colours, both vec3, interleaved.
constexpr int kStride = 6;

const char* kFlatVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 color;
uniform mat4 mvp;
uniform float point_size;
out vec3 vertex_color;
void main() {
  gl_Position = mvp * vec4(position, 1.0);
  gl_PointSize = point_size;
  vertex_color = color;
})";
const char* kFlatFragment = R"(#version 330 core
in vec3 vertex_color;
out vec4 frag_color;
void main() { frag_color = vec4(vertex_color, 1.0); })";

// Flat shading from screen-space derivatives: no normals to upload, and a headlight so
// every face the camera sees is lit.
const char* kMeshVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 color;
uniform mat4 mvp;
uniform mat4 view;
out vec3 vertex_color;
out vec3 eye_position;
void main() {
  gl_Position = mvp * vec4(position, 1.0);
  eye_position = (view * vec4(position, 1.0)).xyz;
  vertex_color = color;
})";
const char* kMeshFragment = R"(#version 330 core
in vec3 vertex_color;
in vec3 eye_position;
out vec4 frag_color;
void main() {
  vec3 n = normalize(cross(dFdx(eye_position), dFdy(eye_position)));
  float light = abs(dot(n, normalize(-eye_position)));
  frag_color = vec4(vertex_color * (0.35 + 0.65 * light), 1.0);
})";

void AddVertex(std::vector<float>* out, const Eigen::Vector3d& p,
               const Eigen::Vector3f& color) {
  out->insert(out->end(), {static_cast<float>(p.x()), static_cast<float>(p.y()),
                           static_cast<float>(p.z()), color.x(), color.y(), color.z()});
}

void AddLine(std::vector<float>* out, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3f& color) {
  AddVertex(out, a, color);
  AddVertex(out, b, color);
}

// A frustum of depth `size`: four edges from the centre, the image rectangle, and a
// small triangle above the image's top edge that shows which way is up.
void AddFrustum(std::vector<float>* out, const PinholeCamera& c, double size,
                const Eigen::Vector3f& color) {
  const double depth = size;
  const Eigen::Vector3d o = c.Center();
  const Eigen::Vector3d p00 = c.Unproject(0, 0, depth);
  const Eigen::Vector3d p10 = c.Unproject(c.width, 0, depth);
  const Eigen::Vector3d p11 = c.Unproject(c.width, c.height, depth);
  const Eigen::Vector3d p01 = c.Unproject(0, c.height, depth);
  for (const Eigen::Vector3d& p : {p00, p10, p11, p01}) AddLine(out, o, p, color);
  AddLine(out, p00, p10, color);
  AddLine(out, p10, p11, color);
  AddLine(out, p11, p01, color);
  AddLine(out, p01, p00, color);
  const Eigen::Vector3d top = c.Unproject(0.5 * c.width, -0.25 * c.height, depth);
  AddLine(out, p00, top, color);
  AddLine(out, top, p10, color);
}

Eigen::Matrix4f ToFloat(const Eigen::Matrix4d& m) { return m.cast<float>(); }

}  // namespace

SceneView::SceneView(QWidget* parent) : QOpenGLWidget(parent) {
  setFocusPolicy(Qt::StrongFocus);
  setMinimumSize(320, 240);
}

SceneView::~SceneView() {
  if (!gl_ready_) return;
  makeCurrent();
  for (Batch* b : {&points_, &cameras_, &mesh_, &overlays_}) {
    b->vao.destroy();
    b->vertices.destroy();
    b->indices.destroy();
  }
  flat_program_.reset();
  mesh_program_.reset();
  doneCurrent();
}

void SceneView::SetContents(std::shared_ptr<const WorkspaceContents> contents) {
  contents_ = std::move(contents);
  highlighted_.clear();
  keyframes_.clear();
  path_preview_.clear();
  live_image_ = QImage();
  live_caption_.clear();
  scene_dirty_ = overlays_dirty_ = true;
  ResetView();
}

void SceneView::ResetView() {
  if (!contents_ || contents_->cameras.empty()) {
    camera_.LookAt({0, 0, -3}, {0, 0, 0}, {0, -1, 0});
  } else {
    // Through the first registered camera (outside a room scene the walls would hide
    // everything), focused at the scene centre so that orbiting turns around it.
    const PinholeCamera& first = contents_->cameras.front();
    camera_.LookThrough(first, std::max(first.WorldToCamera(Eigen::Vector3d::Zero()).z(),
                                        0.25 * contents_->scale));
  }
  update();
  Q_EMIT viewChanged();
}

void SceneView::ShowOverview() {
  if (!contents_ || contents_->cameras.empty()) return ResetView();
  // Per-coordinate median of points and camera centres: robust to stray points.
  std::vector<Eigen::Vector3d> xs = contents_->points;
  for (const PinholeCamera& c : contents_->cameras) xs.push_back(c.Center());
  Eigen::Vector3d middle;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    for (const Eigen::Vector3d& x : xs) v.push_back(x[k]);
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    middle[k] = v[v.size() / 2];
  }
  std::vector<double> distances;
  for (const Eigen::Vector3d& x : xs) distances.push_back((x - middle).norm());
  const size_t at = distances.size() * 9 / 10;
  std::nth_element(distances.begin(), distances.begin() + at, distances.end());
  const double radius = std::max(distances[at], 1e-6);
  const Eigen::Vector3d& up = contents_->up;
  Eigen::Vector3d back = -contents_->cameras.front().ViewDirection();
  back = (back - back.dot(up) * up).normalized();
  if (!back.allFinite()) back = up.unitOrthogonal();
  camera_.set_fov_y(50.0 * M_PI / 180.0);
  camera_.LookAt(middle + 1.8 * radius * up + 1.6 * radius * back, middle, up);
  update();
  Q_EMIT viewChanged();
}

void SceneView::LookThroughCamera(int index) {
  if (!contents_ || index < 0 || index >= contents_->num_views()) return;
  const PinholeCamera& c = contents_->cameras[index];
  // Focus where the camera looks at the scene centre's depth, so orbiting stays sensible.
  const double focus =
      std::max(c.WorldToCamera(Eigen::Vector3d::Zero()).z(), 0.25 * contents_->scale);
  camera_.LookThrough(c, focus);
  update();
  Q_EMIT viewChanged();
}

void SceneView::SetShowPoints(bool show) { show_points_ = show, update(); }
void SceneView::SetShowCameras(bool show) { show_cameras_ = show, update(); }
void SceneView::SetShowMesh(bool show) { show_mesh_ = show, update(); }

void SceneView::SetHighlighted(std::vector<int> indices) {
  highlighted_ = std::move(indices);
  overlays_dirty_ = true;
  update();
}

void SceneView::SetKeyframes(std::vector<PinholeCamera> cameras) {
  keyframes_ = std::move(cameras);
  overlays_dirty_ = true;
  update();
}

void SceneView::SetPathPreview(std::vector<Eigen::Vector3d> centers) {
  path_preview_ = std::move(centers);
  overlays_dirty_ = true;
  update();
}

PinholeCamera SceneView::ViewCamera() const {
  return camera_.ToPinhole(std::max(width(), 1), std::max(height(), 1));
}

void SceneView::initializeGL() {
  initializeOpenGLFunctions();
  flat_program_ = std::make_unique<QOpenGLShaderProgram>();
  flat_program_->addShaderFromSourceCode(QOpenGLShader::Vertex, kFlatVertex);
  flat_program_->addShaderFromSourceCode(QOpenGLShader::Fragment, kFlatFragment);
  flat_program_->link();
  mesh_program_ = std::make_unique<QOpenGLShaderProgram>();
  mesh_program_->addShaderFromSourceCode(QOpenGLShader::Vertex, kMeshVertex);
  mesh_program_->addShaderFromSourceCode(QOpenGLShader::Fragment, kMeshFragment);
  mesh_program_->link();
  for (Batch* b : {&points_, &cameras_, &mesh_, &overlays_}) {
    b->vao.create();
    b->vertices.create();
    b->indices.create();
  }
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_PROGRAM_POINT_SIZE);
  gl_ready_ = true;
  scene_dirty_ = overlays_dirty_ = true;
}

void SceneView::resizeGL(int, int) { Q_EMIT viewChanged(); }

void SceneView::Upload(Batch* batch, const std::vector<float>& interleaved,
                       const std::vector<unsigned int>& indices) {
  batch->vao.bind();
  batch->vertices.bind();
  batch->vertices.allocate(interleaved.data(),
                           static_cast<int>(interleaved.size() * sizeof(float)));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, kStride * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, kStride * sizeof(float),
                        reinterpret_cast<void*>(3 * sizeof(float)));
  if (!indices.empty()) {
    batch->indices.bind();
    batch->indices.allocate(indices.data(),
                            static_cast<int>(indices.size() * sizeof(unsigned int)));
    batch->count = static_cast<int>(indices.size());
  } else {
    batch->count = static_cast<int>(interleaved.size() / kStride);
  }
  batch->vao.release();
}

void SceneView::UploadScene() {
  scene_dirty_ = false;
  std::vector<float> data;
  if (contents_) {
    for (size_t i = 0; i < contents_->points.size(); ++i) {
      const Vector3ub& c = contents_->point_colors[i];
      AddVertex(&data, contents_->points[i], c.cast<float>() / 255.0f);
    }
  }
  Upload(&points_, data, {});

  data.clear();
  if (contents_) {
    for (const PinholeCamera& c : contents_->cameras) {
      AddFrustum(&data, c, 0.06 * contents_->scale, {0.85f, 0.1f, 0.1f});
    }
  }
  Upload(&cameras_, data, {});

  data.clear();
  std::vector<unsigned int> indices;
  if (contents_ && !contents_->mesh.faces.empty()) {
    const TriangleMesh& mesh = contents_->mesh;
    const bool colored = mesh.colors.size() == mesh.vertices.size();
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      AddVertex(&data, mesh.vertices[i],
                colored ? Eigen::Vector3f(mesh.colors[i].cast<float>() / 255.0f)
                        : Eigen::Vector3f(0.7f, 0.7f, 0.72f));
    }
    indices.reserve(mesh.faces.size() * 3);
    for (const Eigen::Vector3i& f : mesh.faces) {
      for (int k = 0; k < 3; ++k) indices.push_back(static_cast<unsigned int>(f[k]));
    }
  }
  Upload(&mesh_, data, indices);
}

void SceneView::UploadOverlays() {
  overlays_dirty_ = false;
  std::vector<float> data;
  if (contents_) {
    const double size = 0.06 * contents_->scale;
    for (int i : highlighted_) {
      if (i >= 0 && i < contents_->num_views()) {
        AddFrustum(&data, contents_->cameras[i], 1.3 * size, {1.0f, 0.85f, 0.0f});
      }
    }
    for (const PinholeCamera& c : keyframes_) {
      AddFrustum(&data, c, 1.2 * size, {0.1f, 0.5f, 1.0f});
    }
    for (size_t i = 1; i < path_preview_.size(); ++i) {
      AddLine(&data, path_preview_[i - 1], path_preview_[i], {0.1f, 0.9f, 0.9f});
    }
  }
  Upload(&overlays_, data, {});
}

void SceneView::Draw(QOpenGLShaderProgram* program, Batch* batch, unsigned int mode,
                     const Eigen::Matrix4d& mvp, bool indexed) {
  if (batch->count == 0) return;
  program->bind();
  const Eigen::Matrix4f m = ToFloat(mvp);
  glUniformMatrix4fv(program->uniformLocation("mvp"), 1, GL_FALSE, m.data());
  batch->vao.bind();
  if (indexed) {
    glDrawElements(mode, batch->count, GL_UNSIGNED_INT, nullptr);
  } else {
    glDrawArrays(mode, 0, batch->count);
  }
  batch->vao.release();
  program->release();
}

void SceneView::SetLiveEnabled(bool on) {
  live_enabled_ = on;
  update();
}

void SceneView::SetLiveImage(QImage image, const QString& caption) {
  live_image_ = std::move(image);
  live_caption_ = caption;
  update();
}

void SceneView::ClearLiveImage() {
  live_image_ = QImage();
  live_caption_.clear();
  update();
}

void SceneView::PaintLiveImage() {
  // The frame has the widget's aspect (it is rendered for ViewCamera()); a live frame is
  // smaller and is scaled up bilinearly.
  QPainter painter(this);
  painter.setRenderHint(QPainter::SmoothPixmapTransform);
  painter.drawImage(rect(), live_image_);
  if (live_caption_.isEmpty()) return;
  const QRect box = painter.fontMetrics()
                        .boundingRect(rect().adjusted(8, 8, -8, -8),
                                      Qt::AlignLeft | Qt::AlignTop, live_caption_)
                        .adjusted(-5, -3, 5, 3);
  painter.fillRect(box, QColor(0, 0, 0, 150));
  painter.setPen(QColor(235, 235, 235));
  painter.drawText(box, Qt::AlignCenter, live_caption_);
}

void SceneView::paintGL() {
  glClearColor(0.16f, 0.17f, 0.19f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (showing_live_image()) return PaintLiveImage();
  // QPainter (the live image) leaves its own state behind.
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  const qreal ratio = devicePixelRatioF();
  glViewport(0, 0, static_cast<int>(width() * ratio), static_cast<int>(height() * ratio));
  if (!gl_ready_ || !flat_program_->isLinked() || !mesh_program_->isLinked()) return;
  if (scene_dirty_) UploadScene();
  if (overlays_dirty_) UploadOverlays();
  if (!contents_) return;

  const double scale = contents_->scale;
  const double distance = std::max(camera_.center().norm(), camera_.focus_distance());
  const double far_plane = 10.0 * (distance + 5.0 * scale);
  const double near_plane = std::max(far_plane * 1e-5, 1e-4 * scale);
  const double aspect = static_cast<double>(std::max(width(), 1)) / std::max(height(), 1);
  const Eigen::Matrix4d view = camera_.ViewMatrix();
  const Eigen::Matrix4d mvp =
      camera_.ProjectionMatrix(aspect, near_plane, far_plane) * view;

  if (show_mesh_) {
    mesh_program_->bind();
    const Eigen::Matrix4f v = ToFloat(view);
    glUniformMatrix4fv(mesh_program_->uniformLocation("view"), 1, GL_FALSE, v.data());
    Draw(mesh_program_.get(), &mesh_, GL_TRIANGLES, mvp, true);
  }
  flat_program_->bind();
  glUniform1f(flat_program_->uniformLocation("point_size"),
              static_cast<float>(2.0 * devicePixelRatioF()));
  if (show_points_) Draw(flat_program_.get(), &points_, GL_POINTS, mvp, false);
  if (show_cameras_) Draw(flat_program_.get(), &cameras_, GL_LINES, mvp, false);
  Draw(flat_program_.get(), &overlays_, GL_LINES, mvp, false);
}

void SceneView::mousePressEvent(QMouseEvent* event) {
  press_position_ = last_position_ = event->pos();
  dragged_ = false;
  setFocus();
}

void SceneView::mouseMoveEvent(QMouseEvent* event) {
  const QPoint delta = event->pos() - last_position_;
  last_position_ = event->pos();
  if ((event->pos() - press_position_).manhattanLength() > 3) dragged_ = true;
  if (!dragged_) return;
  const double h = std::max(height(), 1);
  const bool pan =
      (event->buttons() & (Qt::RightButton | Qt::MiddleButton)) ||
      ((event->buttons() & Qt::LeftButton) && (event->modifiers() & Qt::ShiftModifier));
  if (pan) {
    camera_.Pan(delta.x() / h, delta.y() / h);
  } else if (event->buttons() & Qt::LeftButton) {
    const Eigen::Vector3d up = contents_ ? contents_->up : Eigen::Vector3d(0, -1, 0);
    camera_.Orbit(M_PI * delta.x() / h, M_PI * delta.y() / h, up);
  } else {
    return;
  }
  update();
  Q_EMIT viewChanged();
}

void SceneView::mouseReleaseEvent(QMouseEvent* event) {
  if (dragged_ || event->button() != Qt::LeftButton || !contents_) return;
  // ViewCamera() is in widget (logical) pixels, as mouse events are.
  const int index = PickCamera(contents_->cameras, ViewCamera(), event->pos().x(),
                               event->pos().y(), 12.0);
  if (index < 0) return;
  LookThroughCamera(index);
  Q_EMIT cameraClicked(index);
}

void SceneView::wheelEvent(QWheelEvent* event) {
  const double steps = event->angleDelta().y() / 120.0;
  camera_.Zoom(std::pow(0.85, steps));
  update();
  Q_EMIT viewChanged();
}

void SceneView::keyPressEvent(QKeyEvent* event) {
  const double step = 0.05 * (contents_ ? contents_->scale : 1.0) *
                      ((event->modifiers() & Qt::ShiftModifier) ? 5.0 : 1.0);
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  switch (event->key()) {
    case Qt::Key_W:
      offset.z() = step;
      break;
    case Qt::Key_S:
      offset.z() = -step;
      break;
    case Qt::Key_A:
      offset.x() = -step;
      break;
    case Qt::Key_D:
      offset.x() = step;
      break;
    case Qt::Key_Q:
      offset.y() = step;
      break;
    case Qt::Key_E:
      offset.y() = -step;
      break;
    default:
      QOpenGLWidget::keyPressEvent(event);
      return;
  }
  camera_.Fly(offset);
  update();
  Q_EMIT viewChanged();
}

}  // namespace fvs::ui
