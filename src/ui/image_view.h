// A picture that scales to its widget keeping its aspect ratio, with a caption above it:
// the rendered view and the nearest source photo of the result panel.
#pragma once

#include <QImage>
#include <QString>
#include <QWidget>

#include "fvs/util/image.h"

namespace fvs::ui {

// fvs::Image (1 or 3 channels, values in [0, 1]; others are clamped) -> 8-bit RGB.
QImage ToQImage(const Image& image);

class ImageView : public QWidget {
  Q_OBJECT

 public:
  explicit ImageView(QWidget* parent = nullptr);
  void SetImage(const QImage& image, const QString& caption);
  void Clear(const QString& caption);
  const QImage& image() const { return image_; }
  const QString& caption() const { return caption_; }

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  QImage image_;
  QString caption_;
};

}  // namespace fvs::ui
