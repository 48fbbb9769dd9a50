// The result of "Render novel view": the rendered view (colour, target depth or
// confidence) beside its nearest source photo, the time of each stage, and the sources
// used, which are also highlighted in the 3D view.
#pragma once

#include <QWidget>
#include <memory>

#include "ui/novel_view.h"
#include "ui/workspace_contents.h"

class QButtonGroup;
class QCheckBox;
class QLabel;

namespace fvs::ui {

class ImageView;
class SceneView;

class ResultPanel : public QWidget {
  Q_OBJECT

 public:
  // `scene_view` gets the highlighted sources.
  ResultPanel(SceneView* scene_view, QWidget* parent);

  // Shows a render of `contents`; null clears the panel.
  void Show(std::shared_ptr<const RenderedView> view,
            std::shared_ptr<const WorkspaceContents> contents);

 private:
  void Refresh();

  SceneView* scene_view_;
  std::shared_ptr<const RenderedView> view_;
  std::shared_ptr<const WorkspaceContents> contents_;
  ImageView* result_view_ = nullptr;
  ImageView* source_view_ = nullptr;
  QButtonGroup* layer_group_ = nullptr;
  QCheckBox* show_sources_ = nullptr;
  QLabel* info_ = nullptr;
};

}  // namespace fvs::ui
