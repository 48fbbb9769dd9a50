#include "ui/image_view.h"

#include <QPainter>
#include <algorithm>
#include <cmath>

namespace fvs::ui {

QImage ToQImage(const Image& image) {
  if (image.empty() || (image.channels != 1 && image.channels != 3)) return QImage();
  QImage out(image.width, image.height, QImage::Format_RGB888);
  for (int y = 0; y < image.height; ++y) {
    uchar* line = out.scanLine(y);
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = image.at(x, y, image.channels == 1 ? 0 : c);
        const float clamped = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
        line[3 * x + c] = static_cast<uchar>(std::lround(255.0f * clamped));
      }
    }
  }
  return out;
}

ImageView::ImageView(QWidget* parent) : QWidget(parent) {
  setMinimumSize(160, 120);
  setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
}

void ImageView::SetImage(const QImage& image, const QString& caption) {
  image_ = image;
  caption_ = caption;
  update();
}

void ImageView::Clear(const QString& caption) { SetImage(QImage(), caption); }

void ImageView::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(rect(), QColor(40, 42, 46));
  const int caption_height = fontMetrics().height() + 6;
  painter.setPen(QColor(220, 220, 220));
  painter.drawText(QRect(4, 0, width() - 8, caption_height),
                   Qt::AlignVCenter | Qt::AlignLeft, caption_);
  if (image_.isNull()) return;
  const QRect area(0, caption_height, width(), std::max(height() - caption_height, 1));
  QSize size = image_.size();
  size.scale(area.size(), Qt::KeepAspectRatio);
  const QRect target(area.x() + (area.width() - size.width()) / 2,
                     area.y() + (area.height() - size.height()) / 2, size.width(),
                     size.height());
  painter.setRenderHint(QPainter::SmoothPixmapTransform);
  painter.drawImage(target, image_);
}

}  // namespace fvs::ui
