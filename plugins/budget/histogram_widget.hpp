#pragma once
// Depth-complexity histogram drawn with QPainter: pixels per fragment count n (log scale), the
// chosen k marked, the counts beyond k (fragments a k-buffer cannot keep) tinted.
#include <QSize>
#include <QVector>
#include <QWidget>

class HistogramWidget final : public QWidget {
  Q_OBJECT

 public:
  explicit HistogramWidget(QWidget* parent = nullptr);
  void setHistogram(const QVector<quint64>& histogram, QSize imageSize);
  // 0: none. variable: k differs per pixel (vkb, dkb, kplus-sbuffer…) and k is its maximum, so
  // pixels with n ≤ k may lose fragments too: the bars are not split into kept and lost.
  void setMarker(int k, bool variable = false);
  [[nodiscard]] const QVector<quint64>& histogram() const { return histogram_; }
  [[nodiscard]] QString title() const;  // what the widget's first line says (its accessible name)

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  QVector<quint64> histogram_;
  QSize imageSize_;
  bool received_ = false;  // a count has come (an empty one: nothing visible)
  int marker_ = 0;
  bool variable_ = false;
};
