#pragma once
// Widgets drawn over the render view: a colour legend for heat maps, a caption per compare pane
// and the draggable line of the split layout. They are child widgets, not pixels of the image,
// so the view's framebuffer stays exactly what mfrcore rendered.
#include <QLabel>
#include <QWidget>

#include <vector>

// Colour bar of a heat map (the magma map of mfr::heatmap) or of the colour map a field is shown
// with, with its title and value range, or only a note (e.g. "no k(p) for this method").
class MapLegend final : public QWidget {
  Q_OBJECT

 public:
  explicit MapLegend(QWidget* parent = nullptr);
  // The bar spans 0 … scaleMax; `range` is the text under it (e.g. "min 0 · max 14").
  void setMap(const QString& title, double scaleMax, const QString& range);
  void setNote(const QString& title, const QString& note);
  // The bar of a surface colour map (mfr::colorMap) from `low` to `high`: a field's colour legend.
  // `ticks`: values marked on the bar (the isosurfaces'), none when empty.
  void setFieldMap(const QString& title, const QString& map, double low, double high, const QString& text,
                   const std::vector<double>& ticks = {});
  [[nodiscard]] const std::vector<double>& ticks() const { return ticks_; }
  [[nodiscard]] const QString& mapName() const { return map_; }
  [[nodiscard]] const QString& title() const { return title_; }
  [[nodiscard]] const QString& text() const { return text_; }
  [[nodiscard]] QSize sizeHint() const override;

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  QString title_, text_;
  double scaleMin_ = 0.0, scaleMax_ = 1.0;
  QString map_;  // empty: magma (heat maps)
  std::vector<double> ticks_;
  bool bar_ = false;
};

// The caption of a compare pane: method and its metrics against the exact image.
class PaneCaption final : public QLabel {
  Q_OBJECT

 public:
  explicit PaneCaption(QWidget* parent = nullptr);
};

// The vertical line between the two images of the split layout; dragging it moves the split.
class SplitHandle final : public QWidget {
  Q_OBJECT

 public:
  explicit SplitHandle(QWidget* parent = nullptr);
  static constexpr int kWidth = 9;

 signals:
  void dragged(int parentX);  // the line's new x in the parent's coordinates

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
};

// The pixel probe's mark: a small cross in a ring centred on the probed point. Transparent for the
// mouse, so navigation and further probes go to the view under it.
class ProbeMarker final : public QWidget {
  Q_OBJECT

 public:
  explicit ProbeMarker(QWidget* parent = nullptr);
  static constexpr int kSize = 17;
  void setCentre(QPoint centre);  // in the parent's coordinates

 protected:
  void paintEvent(QPaintEvent* event) override;
};
