#include "histogram_widget.hpp"

#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cmath>

HistogramWidget::HistogramWidget(QWidget* parent) : QWidget(parent) {
  setMinimumSize(220, 150);
  setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
  setAccessibleName(title());
}

void HistogramWidget::setHistogram(const QVector<quint64>& histogram, QSize imageSize) {
  histogram_ = histogram;
  imageSize_ = imageSize;
  received_ = true;
  setAccessibleName(title());  // the title, also for screen readers (the bars are painted)
  update();
}

QString HistogramWidget::title() const {
  if (!received_) return tr("Depth complexity: computing…");
  // An empty count: nothing to draw (every part hidden, a clip box that holds nothing); it read
  // "computing…" for ever (a bug hunt).
  if (histogram_.isEmpty()) return tr("Depth complexity: nothing visible");
  return tr("Depth complexity n(p), GPU count (%1×%2)").arg(imageSize_.width()).arg(imageSize_.height());
}

void HistogramWidget::setMarker(int k, bool variable) {
  if (k == marker_ && variable == variable_) return;
  marker_ = k;
  variable_ = variable;
  update();
}

void HistogramWidget::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing, false);
  const QPalette pal = palette();
  p.fillRect(rect(), pal.base());
  const QFontMetrics fm = fontMetrics();
  quint64 largest = 1;
  for (qsizetype n = 1; n < histogram_.size(); ++n) largest = std::max(largest, histogram_[n]);
  const QRect plot =
      // Room above for the title and half the top value's label, which is centred on the top.
      rect().adjusted(fm.horizontalAdvance(QString::number(largest)) + 10, 2 * fm.height() + 4, -10,
                      -2 * fm.height() - 8);
  p.setPen(pal.color(QPalette::Text));
  p.drawText(QRect(4, 2, width() - 8, fm.height() + 4), Qt::AlignLeft | Qt::AlignVCenter, title());
  if (histogram_.size() < 2 || plot.width() < 20 || plot.height() < 20) return;

  // Pixels with n ≥ 1 only: empty pixels would dwarf everything and cost no memory per fragment.
  const int maxN = static_cast<int>(histogram_.size()) - 1;
  quint64 maxCount = 1;
  for (int n = 1; n <= maxN; ++n) maxCount = std::max(maxCount, histogram_[n]);
  const double logMax = std::log10(static_cast<double>(maxCount) + 1.0);
  const double barWidth = static_cast<double>(plot.width()) / maxN;
  const QColor kept = pal.color(QPalette::Highlight);
  const QColor lost(230, 120, 40);
  for (int n = 1; n <= maxN; ++n) {
    if (histogram_[n] == 0) continue;
    const double h = plot.height() * std::log10(static_cast<double>(histogram_[n]) + 1.0) / logMax;
    const QRectF bar(plot.left() + (n - 1) * barWidth, plot.bottom() - h,
                     std::max(1.0, barWidth - (barWidth > 4 ? 1 : 0)), h);
    p.fillRect(bar, marker_ > 0 && !variable_ && n > marker_ ? lost : kept);
  }
  // Axes and labels.
  p.setPen(pal.color(QPalette::Mid));
  p.drawLine(plot.bottomLeft(), plot.bottomRight());
  p.drawLine(plot.bottomLeft(), plot.topLeft());
  p.setPen(pal.color(QPalette::Text));
  for (int n : {1, (maxN + 1) / 2, maxN}) {
    const int x = static_cast<int>(plot.left() + (n - 0.5) * barWidth);
    p.drawText(QRect(x - 30, plot.bottom() + 2, 60, fm.height()), Qt::AlignHCenter | Qt::AlignTop, QString::number(n));
  }
  p.drawText(QRect(0, plot.top() - fm.height() / 2, plot.left() - 4, fm.height()), Qt::AlignRight | Qt::AlignVCenter,
             QString::number(maxCount));
  p.drawText(QRect(0, plot.bottom() - fm.height() / 2, plot.left() - 4, fm.height()), Qt::AlignRight | Qt::AlignVCenter,
             QStringLiteral("0"));
  p.drawText(QRect(plot.left(), plot.bottom() + fm.height() + 4, plot.width(), fm.height()),
             Qt::AlignHCenter | Qt::AlignTop, tr("fragments per pixel n; bars: pixels (log scale)"));
  if (marker_ > 0 && marker_ <= maxN) {
    const int x = static_cast<int>(plot.left() + marker_ * barWidth);
    p.setPen(QPen(QColor(200, 30, 30), 2, Qt::DashLine));
    p.drawLine(x, plot.top(), x, plot.bottom());
    const QString label = variable_ ? tr("max k(p) = %1").arg(marker_) : QStringLiteral("k = %1").arg(marker_);
    // Right of the line, or left of it where the plot ends; on the background colour, so that it
    // reads over the bars.
    const int labelWidth = fm.horizontalAdvance(label) + 8;
    const int left = x + 4 + labelWidth <= plot.right() ? x + 4 : std::max(plot.left(), x - 4 - labelWidth);
    const QRect box(left, plot.top(), labelWidth, fm.height());
    QColor backing = pal.color(QPalette::Base);
    backing.setAlpha(220);
    p.fillRect(box, backing);
    p.drawText(box, Qt::AlignHCenter | Qt::AlignVCenter, label);
  }
}
