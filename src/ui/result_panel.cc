#include "ui/result_panel.h"

#include <QButtonGroup>
#include <QCheckBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QRadioButton>
#include <QStringList>
#include <QVBoxLayout>
#include <algorithm>

#include "fvs/render/render_output.h"
#include "ui/image_view.h"
#include "ui/scene_view.h"

namespace fvs::ui {
namespace {

QString Seconds(double s) { return QString::number(s, 'f', s < 10 ? 2 : 1) + " s"; }

}  // namespace

ResultPanel::ResultPanel(SceneView* scene_view, QWidget* parent)
    : QWidget(parent), scene_view_(scene_view) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  auto* images = new QHBoxLayout();
  result_view_ = new ImageView(this);
  result_view_->setObjectName("result_view");
  source_view_ = new ImageView(this);
  source_view_->setObjectName("source_view");
  images->addWidget(result_view_);
  images->addWidget(source_view_);
  layout->addLayout(images, 1);

  auto* toggles = new QHBoxLayout();
  layer_group_ = new QButtonGroup(this);
  const char* names[] = {"Colour", "Target depth", "Confidence"};
  const char* object_names[] = {"layer_color", "layer_depth", "layer_confidence"};
  for (int i = 0; i < 3; ++i) {
    auto* button = new QRadioButton(names[i], this);
    button->setObjectName(object_names[i]);
    button->setChecked(i == 0);
    layer_group_->addButton(button, i);
    toggles->addWidget(button);
  }
  connect(layer_group_, &QButtonGroup::idClicked, this, [this] { Refresh(); });
  show_sources_ = new QCheckBox("Show sources used", this);
  show_sources_->setObjectName("show_sources");
  show_sources_->setChecked(true);
  connect(show_sources_, &QCheckBox::toggled, this, [this] { Refresh(); });
  toggles->addWidget(show_sources_);
  toggles->addStretch(1);
  layout->addLayout(toggles);
  info_ = new QLabel(this);
  info_->setObjectName("render_info");
  info_->setWordWrap(true);
  info_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(info_);
  Refresh();
}

void ResultPanel::Show(std::shared_ptr<const RenderedView> view,
                       std::shared_ptr<const WorkspaceContents> contents) {
  view_ = std::move(view);
  contents_ = std::move(contents);
  Refresh();
}

void ResultPanel::Refresh() {
  if (!view_ || !contents_ || !contents_->scene) {
    result_view_->Clear("Rendered view");
    source_view_->Clear("Nearest source photo");
    info_->clear();
    scene_view_->SetHighlighted({});
    return;
  }
  const RenderedView& view = *view_;
  const RenderResult& r = view.result;
  const QString size = QString("%1x%2").arg(view.camera.width).arg(view.camera.height);
  const QString method = QString::fromStdString(view.method);
  switch (layer_group_->checkedId()) {
    case 1:
      result_view_->SetImage(ToQImage(FalseColourDepth(r.depth)),
                             "Target depth from the mesh (" + size + ", near = warm)");
      break;
    case 2:
      result_view_->SetImage(ToQImage(r.confidence),
                             "Confidence (" + method + ", " + size + ")");
      break;
    default:
      result_view_->SetImage(ToQImage(r.color), "Rendered: " + method + ", " + size);
  }
  const Scene& scene = *contents_->scene;
  if (view.nearest_view >= 0) {
    source_view_->SetImage(
        ToQImage(view.nearest_photo),
        QString("Nearest source: %1 (sees %2 % of the view)")
            .arg(QString::fromStdString(scene.view(view.nearest_view).name))
            .arg(100.0 * r.sources.front().fraction, 0, 'f', 1));
  } else {
    source_view_->Clear("Nearest source: no source sees this view");
  }

  double covered = 0;
  for (float c : r.coverage.data) covered += c;
  covered /= std::max<size_t>(1, r.coverage.data.size());
  const RenderTimings& t = r.timings;
  QString info = QString(
                     "%1, K = %2, %3: %4 (depth %5, selection %6, warp %7, encode "
                     "%8, blend %9); %10 % of pixels covered")
                     .arg(method)
                     .arg(view.num_sources)
                     .arg(size)
                     .arg(Seconds(view.seconds))
                     .arg(Seconds(t.depth_s))
                     .arg(Seconds(t.selection_s))
                     .arg(Seconds(t.warp_s))
                     .arg(Seconds(t.encode_s))
                     .arg(Seconds(t.blend_s))
                     .arg(100.0 * covered, 0, 'f', 1);
  std::vector<int> highlighted;
  if (show_sources_->isChecked()) {
    QStringList sources;
    for (const SourceScore& s : r.sources) {
      const std::string& name = scene.view(s.view_index).name;
      sources << QString("%1 (%2 %)")
                     .arg(QString::fromStdString(name))
                     .arg(100.0 * s.fraction, 0, 'f', 1);
      const auto it =
          std::find(contents_->view_names.begin(), contents_->view_names.end(), name);
      if (it != contents_->view_names.end()) {
        highlighted.push_back(static_cast<int>(it - contents_->view_names.begin()));
      }
    }
    info += "\nSources used (yellow in the 3D view): " +
            (sources.isEmpty() ? QString("none") : sources.join(", "));
  }
  info_->setText(info);
  scene_view_->SetHighlighted(highlighted);
}

}  // namespace fvs::ui
