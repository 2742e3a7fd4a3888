#include "view_overlays.hpp"

#include <QLinearGradient>
#include <QMouseEvent>
#include <QPainter>

#include <algorithm>
#include <cmath>

#include "mfr/reference/metrics.hpp"
#include "mfr/scene/color_map.hpp"

namespace {

// The magma colours mfr::heatmap uses, as gradient stops.
QLinearGradient magmaGradient(QPointF from, QPointF to) {
  static const mfr::ImageRGBA8 ramp = [] {
    mfr::ImageF values(256, 1, 1);
    for (int i = 0; i < 256; ++i) values.at(i, 0) = static_cast<float>(i) / 255.0f;
    return mfr::magma(values);
  }();
  QLinearGradient gradient(from, to);
  for (int i = 0; i < 256; i += 15) {
    const std::uint8_t* c = ramp.at(i, 0);
    gradient.setColorAt(i / 255.0, QColor(c[0], c[1], c[2]));
  }
  const std::uint8_t* last = ramp.at(255, 0);
  gradient.setColorAt(1.0, QColor(last[0], last[1], last[2]));
  return gradient;
}

// A surface colour map's table (mfr::colorMap) as gradient stops.
QLinearGradient fieldGradient(const std::string& name, QPointF from, QPointF to) {
  const mfr::ColorMap& map = mfr::colorMap(name);
  QLinearGradient gradient(from, to);
  const auto last = static_cast<int>(map.table.size()) - 1;
  for (int i = 0; i <= last; i += 15) {
    const glm::vec3 c = map.table[static_cast<std::size_t>(i)];
    gradient.setColorAt(static_cast<double>(i) / last, QColor::fromRgbF(c.r, c.g, c.b));
  }
  const glm::vec3 c = map.table.back();
  gradient.setColorAt(1.0, QColor::fromRgbF(c.r, c.g, c.b));
  return gradient;
}

// Overlays paint opaque backgrounds: a translucent child would make every change of its text
// repaint the OpenGL view beneath it.
void makeOpaque(QWidget* widget) {
  widget->setAutoFillBackground(true);
  QPalette p = widget->palette();
  p.setColor(QPalette::Window, QColor(24, 24, 28));
  p.setColor(QPalette::WindowText, QColor(235, 235, 235));
  widget->setPalette(p);
}

}  // namespace

MapLegend::MapLegend(QWidget* parent) : QWidget(parent) {
  makeOpaque(this);
  setAttribute(Qt::WA_TransparentForMouseEvents);
}

void MapLegend::setMap(const QString& title, double scaleMax, const QString& range) {
  title_ = title;
  text_ = range;
  scaleMin_ = 0.0;
  scaleMax_ = scaleMax;
  map_.clear();
  ticks_.clear();
  bar_ = true;
  resize(sizeHint());
  update();
}

void MapLegend::setFieldMap(const QString& title, const QString& map, double low, double high, const QString& text,
                            const std::vector<double>& ticks) {
  ticks_ = ticks;
  title_ = title;
  text_ = text;
  scaleMin_ = low;
  scaleMax_ = high;
  map_ = map;
  bar_ = true;
  resize(sizeHint());
  update();
}

void MapLegend::setNote(const QString& title, const QString& note) {
  title_ = title;
  text_ = note;
  bar_ = false;
  resize(sizeHint());
  update();
}

QSize MapLegend::sizeHint() const {
  const QFontMetrics fm = fontMetrics();
  const int width = std::max({fm.horizontalAdvance(title_), fm.horizontalAdvance(text_), 160}) + 16;
  return {width, fm.height() * 2 + (bar_ ? 14 + fm.height() : 0) + 12};
}

void MapLegend::paintEvent(QPaintEvent*) {
  QPainter p(this);
  const QFontMetrics fm = fontMetrics();
  p.setPen(palette().color(QPalette::WindowText));
  int y = 4;
  p.drawText(QRect(8, y, width() - 16, fm.height()), Qt::AlignLeft | Qt::AlignVCenter, title_);
  y += fm.height() + 2;
  if (bar_) {
    const QRect bar(8, y, width() - 16, 12);
    p.fillRect(bar, map_.isEmpty() ? magmaGradient(bar.topLeft(), bar.topRight())
                                   : fieldGradient(map_.toStdString(), bar.topLeft(), bar.topRight()));
    p.drawRect(bar.adjusted(0, 0, -1, -1));
    for (const double t : ticks_) {  // a mark across the bar at each value
      if (!(scaleMax_ > scaleMin_)) break;
      const double f = std::clamp((t - scaleMin_) / (scaleMax_ - scaleMin_), 0.0, 1.0);
      const int x = bar.left() + static_cast<int>(std::lround(f * (bar.width() - 1)));
      p.drawLine(x, bar.top() - 2, x, bar.bottom() + 2);
    }
    y += 14;
    p.drawText(QRect(8, y, width() - 16, fm.height()), Qt::AlignLeft | Qt::AlignVCenter,
               QString::number(scaleMin_, 'g', 4));
    p.drawText(QRect(8, y, width() - 16, fm.height()), Qt::AlignRight | Qt::AlignVCenter,
               QString::number(scaleMax_, 'g', 4));
    y += fm.height();
  }
  p.drawText(QRect(8, y, width() - 16, fm.height()), Qt::AlignLeft | Qt::AlignVCenter, text_);
}

PaneCaption::PaneCaption(QWidget* parent) : QLabel(parent) {
  makeOpaque(this);
  setMargin(4);
  setTextFormat(Qt::PlainText);
  setAttribute(Qt::WA_TransparentForMouseEvents);
}

SplitHandle::SplitHandle(QWidget* parent) : QWidget(parent) {
  setCursor(Qt::SplitHCursor);
  setToolTip(tr("Drag to move the split between the two methods"));
  // Opaque too: it covers the line's columns of both images.
  setAttribute(Qt::WA_OpaquePaintEvent);
}

void SplitHandle::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.fillRect(rect(), QColor(24, 24, 28));
  p.fillRect(QRect(width() / 2 - 1, 0, 3, height()), QColor(240, 240, 240));
}

void SplitHandle::mousePressEvent(QMouseEvent* event) {
  event->accept();
}

void SplitHandle::mouseMoveEvent(QMouseEvent* event) {
  if (event->buttons() & Qt::LeftButton) emit dragged(mapToParent(event->position().toPoint()).x());
}

ProbeMarker::ProbeMarker(QWidget* parent) : QWidget(parent) {
  setAttribute(Qt::WA_TransparentForMouseEvents);
  setAttribute(Qt::WA_TranslucentBackground);
  setFixedSize(kSize, kSize);
}

void ProbeMarker::setCentre(QPoint centre) {
  move(centre - QPoint(kSize / 2, kSize / 2));
}

void ProbeMarker::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  const QPointF c(kSize / 2.0, kSize / 2.0);
  // Dark under light, so the mark shows on any image.
  for (const auto& [colour, width] : {std::pair{QColor(0, 0, 0, 200), 3.0}, std::pair{QColor(255, 255, 0), 1.2}}) {
    p.setPen(QPen(colour, width));
    p.drawEllipse(c, kSize / 2.0 - 2.0, kSize / 2.0 - 2.0);
    p.drawLine(QPointF(c.x(), 1.0), QPointF(c.x(), c.y() - 3.0));
    p.drawLine(QPointF(c.x(), c.y() + 3.0), QPointF(c.x(), kSize - 1.0));
    p.drawLine(QPointF(1.0, c.y()), QPointF(c.x() - 3.0, c.y()));
    p.drawLine(QPointF(c.x() + 3.0, c.y()), QPointF(kSize - 1.0, c.y()));
  }
}
