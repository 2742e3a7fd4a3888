#include "transfer_function_editor.hpp"

#include <QColorDialog>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>

#include <algorithm>
#include <cmath>

namespace {

QColor displayColor(const glm::vec4& c, float alpha = 1.0f) {
  return QColor::fromRgbF(c.r, c.g, c.b, alpha);
}

}  // namespace

TransferFunctionEditor::TransferFunctionEditor(QWidget* parent) : QWidget(parent) {
  setFocusPolicy(Qt::StrongFocus);  // arrow keys and Delete act on the selected point
  setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Fixed);
  setToolTip(
      tr("Opacity over the window's values, filled with the colour, over a histogram of the volume (log "
         "scale). Click: add a point; drag: move it; right click or Delete: remove it; double click: its "
         "colour; arrow keys: nudge it. The end points move only vertically."));
}

bool TransferFunctionEditor::editable() const {
  return points_.size() >= 2 && points_.back().value > points_.front().value;
}

glm::vec4 TransferFunctionEditor::colorAt(const std::vector<mfr::TransferPoint>& points, double value) {
  if (points.empty()) return glm::vec4(0.0f);
  if (!(value > points.front().value)) return points.front().color;
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (value > points[i].value) continue;
    const mfr::TransferPoint& a = points[i - 1];
    const mfr::TransferPoint& b = points[i];
    const double t = b.value > a.value ? (value - a.value) / (b.value - a.value) : 1.0;
    return glm::vec4(glm::mix(glm::dvec4(a.color), glm::dvec4(b.color), t));
  }
  return points.back().color;
}

// ---- state ----------------------------------------------------------------------------------

void TransferFunctionEditor::setPoints(const std::vector<mfr::TransferPoint>& points) {
  const bool sameCount = points.size() == points_.size();
  points_ = points;
  if (!sameCount || !editable()) {
    dragged_ = -1;
    if (selected_ != -1) {
      selected_ = -1;
      emit selectionChanged();
    }
  }
  update();
}

void TransferFunctionEditor::setHistogram(const std::vector<std::uint64_t>& counts) {
  histogram_ = counts;
  update();
}

QList<quint64> TransferFunctionEditor::histogramCounts() const {
  return {histogram_.begin(), histogram_.end()};
}

void TransferFunctionEditor::selectPoint(int index) {
  if (index < -1 || index >= static_cast<int>(points_.size()) || index == selected_) return;
  selected_ = index;
  update();
  emit selectionChanged();
}

// ---- edits ----------------------------------------------------------------------------------

int TransferFunctionEditor::addPoint(double value, double opacity) {
  if (!editable() || !std::isfinite(value) || !std::isfinite(opacity)) return -1;
  const auto next = std::upper_bound(points_.begin(), points_.end(), value,
                                     [](double v, const mfr::TransferPoint& p) { return v < p.value; });
  if (next == points_.begin() || next == points_.end()) return -1;  // outside the range, or at its end
  const double gap = kMinGap * (high() - low());
  if (value - std::prev(next)->value < gap || next->value - value < gap) return -1;
  glm::vec4 color = colorAt(points_, value);
  color.a = static_cast<float>(std::clamp(opacity, 0.0, 1.0));
  const auto index = static_cast<int>(next - points_.begin());
  points_.insert(next, mfr::TransferPoint{value, color});
  selected_ = index;
  update();
  emit edited();
  emit selectionChanged();
  return index;
}

bool TransferFunctionEditor::movePoint(int index, double value, double opacity) {
  if (!editable() || index < 0 || index >= static_cast<int>(points_.size())) return false;
  const auto i = static_cast<std::size_t>(index);
  mfr::TransferPoint& p = points_[i];
  double newValue = p.value;
  if (index > 0 && i + 1 < points_.size() && std::isfinite(value)) {
    const double gap = kMinGap * (high() - low());
    const double from = points_[i - 1].value + gap, to = points_[i + 1].value - gap;
    // Neighbours closer than two gaps (a step loaded from a file): the value stays.
    if (from <= to) newValue = std::clamp(value, from, to);
  }
  const float newOpacity = std::isfinite(opacity) ? static_cast<float>(std::clamp(opacity, 0.0, 1.0)) : p.color.a;
  if (newValue == p.value && newOpacity == p.color.a) return false;
  p.value = newValue;
  p.color.a = newOpacity;
  update();
  emit edited();
  return true;
}

bool TransferFunctionEditor::setPointColor(int index, const glm::vec3& rgb) {
  if (!editable() || index < 0 || index >= static_cast<int>(points_.size())) return false;
  mfr::TransferPoint& p = points_[static_cast<std::size_t>(index)];
  const glm::vec3 clamped = glm::clamp(rgb, glm::vec3(0.0f), glm::vec3(1.0f));
  if (glm::vec3(p.color) == clamped) return false;
  p.color = glm::vec4(clamped, p.color.a);
  update();
  emit edited();
  return true;
}

bool TransferFunctionEditor::removePoint(int index) {
  // The ends carry the window, so at least two points always remain.
  if (!editable() || index <= 0 || index + 1 >= static_cast<int>(points_.size()) || points_.size() <= 2) return false;
  points_.erase(points_.begin() + index);
  dragged_ = -1;
  selected_ = -1;
  update();
  emit edited();
  emit selectionChanged();
  return true;
}

void TransferFunctionEditor::editPointColor(int index) {
  if (!editable() || index < 0 || index >= static_cast<int>(points_.size())) return;
  auto* dialog = new QColorDialog(displayColor(points_[static_cast<std::size_t>(index)].color), this);
  dialog->setObjectName(QStringLiteral("hvPointColorDialog"));
  dialog->setWindowTitle(tr("Colour of point %1").arg(index + 1));
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  // Qt's own dialog on every desktop: the same behaviour everywhere, and one the tests can reach.
  dialog->setOption(QColorDialog::DontUseNativeDialog);
  // The points may have changed while it was open (another function set elsewhere): then the
  // index no longer names the same point and the colour is dropped.
  const std::size_t count = points_.size();
  connect(dialog, &QColorDialog::colorSelected, this, [this, index, count](const QColor& c) {
    if (points_.size() == count) setPointColor(index, {c.redF(), c.greenF(), c.blueF()});
  });
  dialog->open();
}

// ---- mapping --------------------------------------------------------------------------------

QRectF TransferFunctionEditor::plotRect() const {
  return {static_cast<double>(kMargin), static_cast<double>(kMargin), std::max(1.0, width() - 2.0 * kMargin),
          std::max(1.0, height() - 2.0 * kMargin)};
}

double TransferFunctionEditor::xForValue(double value) const {
  const QRectF r = plotRect();
  if (!editable()) return r.left();
  return r.left() + (value - low()) / (high() - low()) * r.width();
}

double TransferFunctionEditor::valueForX(double x) const {
  const QRectF r = plotRect();
  if (!editable()) return 0.0;
  return low() + (x - r.left()) / r.width() * (high() - low());
}

double TransferFunctionEditor::yForOpacity(double opacity) const {
  const QRectF r = plotRect();
  return r.bottom() - opacity * r.height();
}

double TransferFunctionEditor::opacityForY(double y) const {
  const QRectF r = plotRect();
  return (r.bottom() - y) / r.height();
}

int TransferFunctionEditor::pointAt(const QPointF& position) const {
  if (!editable()) return -1;
  int best = -1;
  double bestDistance = kHitRadius;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const double d =
        std::hypot(position.x() - xForValue(points_[i].value), position.y() - yForOpacity(points_[i].color.a));
    if (d <= bestDistance) {
      best = static_cast<int>(i);
      bestDistance = d;
    }
  }
  return best;
}

// ---- painting -------------------------------------------------------------------------------

void TransferFunctionEditor::paintEvent(QPaintEvent* /*event*/) {
  QPainter painter(this);
  painter.fillRect(rect(), palette().base());
  const QRectF r = plotRect();
  if (!editable()) {
    painter.setPen(palette().color(QPalette::PlaceholderText));
    painter.drawText(r, Qt::AlignCenter, tr("no transfer function"));
    return;
  }
  // Histogram: log(1 + count), so small populations (thin tissue) stay visible beside the air.
  if (!histogram_.empty()) {
    const double top = std::log1p(static_cast<double>(*std::max_element(histogram_.begin(), histogram_.end())));
    const double binWidth = r.width() / static_cast<double>(histogram_.size());
    if (top > 0.0)
      for (std::size_t b = 0; b < histogram_.size(); ++b) {
        const double h = std::log1p(static_cast<double>(histogram_[b])) / top * r.height();
        painter.fillRect(QRectF(r.left() + static_cast<double>(b) * binWidth, r.bottom() - h, binWidth, h),
                         QColor(170, 170, 170));
      }
  }
  // Colour under the curve, one pixel column at a time (translucent: the histogram shows through).
  for (int x = static_cast<int>(std::floor(r.left())); x < static_cast<int>(std::ceil(r.right())); ++x) {
    const glm::vec4 c = colorAt(points_, valueForX(x + 0.5));
    const double y = yForOpacity(c.a);
    painter.fillRect(QRectF(x, y, 1.0, r.bottom() - y), displayColor(c, 0.7f));
  }
  painter.setPen(palette().color(QPalette::Mid));
  painter.drawRect(r);
  painter.setRenderHint(QPainter::Antialiasing);
  QPolygonF curve;
  for (const mfr::TransferPoint& p : points_) curve << QPointF(xForValue(p.value), yForOpacity(p.color.a));
  painter.setPen(QPen(palette().color(QPalette::Text), 1.5));
  painter.drawPolyline(curve);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const bool selected = static_cast<int>(i) == selected_;
    painter.setPen(selected ? QPen(palette().color(QPalette::Highlight), 3.0)
                            : QPen(palette().color(QPalette::Text), 1.0));
    painter.setBrush(displayColor(points_[i].color));
    painter.drawEllipse(curve[static_cast<qsizetype>(i)], kPointRadius, kPointRadius);
  }
}

// ---- mouse and keys -------------------------------------------------------------------------

void TransferFunctionEditor::mousePressEvent(QMouseEvent* event) {
  if (!editable()) {
    QWidget::mousePressEvent(event);
    return;
  }
  const QPointF pos = event->position();
  const int hit = pointAt(pos);
  if (event->button() == Qt::LeftButton) {
    if (hit >= 0) {
      selectPoint(hit);
      dragged_ = hit;
    } else {
      dragged_ = addPoint(valueForX(pos.x()), opacityForY(pos.y()));
    }
  } else if (event->button() == Qt::RightButton && hit >= 0) {
    removePoint(hit);
  }
  event->accept();
}

void TransferFunctionEditor::mouseMoveEvent(QMouseEvent* event) {
  if (dragged_ < 0 || !(event->buttons() & Qt::LeftButton)) {
    QWidget::mouseMoveEvent(event);
    return;
  }
  movePoint(dragged_, valueForX(event->position().x()), opacityForY(event->position().y()));
  event->accept();
}

void TransferFunctionEditor::mouseReleaseEvent(QMouseEvent* event) {
  if (event->button() == Qt::LeftButton) dragged_ = -1;
  event->accept();
}

void TransferFunctionEditor::mouseDoubleClickEvent(QMouseEvent* event) {
  const int hit = event->button() == Qt::LeftButton ? pointAt(event->position()) : -1;
  if (hit < 0) {
    mousePressEvent(event);
    return;
  }
  dragged_ = -1;
  selectPoint(hit);
  editPointColor(hit);
  event->accept();
}

void TransferFunctionEditor::keyPressEvent(QKeyEvent* event) {
  if (!editable() || selected_ < 0) {
    QWidget::keyPressEvent(event);
    return;
  }
  const mfr::TransferPoint p = points_[static_cast<std::size_t>(selected_)];
  const QRectF r = plotRect();
  const double pixels = (event->modifiers() & Qt::ShiftModifier) ? 10.0 : 1.0;
  const double dValue = pixels * (high() - low()) / r.width(), dOpacity = pixels / r.height();
  switch (event->key()) {
    case Qt::Key_Left:
      movePoint(selected_, p.value - dValue, p.color.a);
      break;
    case Qt::Key_Right:
      movePoint(selected_, p.value + dValue, p.color.a);
      break;
    case Qt::Key_Up:
      movePoint(selected_, p.value, p.color.a + dOpacity);
      break;
    case Qt::Key_Down:
      movePoint(selected_, p.value, p.color.a - dOpacity);
      break;
    case Qt::Key_Delete:
    case Qt::Key_Backspace:
      removePoint(selected_);
      break;
    default:
      QWidget::keyPressEvent(event);
      return;
  }
  event->accept();
}
