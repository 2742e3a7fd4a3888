#pragma once
// The Volume panel's transfer-function editor, after ParaView's colour/opacity editor: a painted plot
// of the function's control points over its own range [low, high] (the panel's window), opacity 0 at
// the bottom and 1 at the top.
// - Background: a histogram of the volume's samples over the range (ViewerContext::volumeHistogram,
//   set by the panel), grey bars of height log(1 + count), so tissue and bone show where they lie.
// - The opacity curve: each point a circle at (value, opacity a) filled with its colour, joined by
//   lines; the area under the curve is filled column by column with the interpolated colour. The
//   opacities are the points' own (per the function's unit distance at the panel's scale 1): the
//   panel's opacity scale divides the unit distance and leaves them alone.
// - Mouse: a left click on empty space adds a point there (colour interpolated between its
//   neighbours) and keeps dragging it while the button is held; dragging a point moves it with the
//   mouse, its value clamped strictly between its neighbours' (kMinGap of the range apart, so values
//   stay ascending) and its opacity to 0 … 1. The first and last points move only vertically and
//   cannot be removed: their values are the window's ends, which the panel's Window sets, and the
//   function therefore always keeps at least two points. A right click on a point removes it, a
//   double click opens a colour dialog for it.
// - Keys on the selected point: Left/Right move its value, Up/Down its opacity by one pixel's worth
//   (ten with Shift); Delete or Backspace removes it.
// Every edit by the user (mouse, keys, or the edit functions below, which the panel's spin boxes
// call) emits edited(); setPoints(), the panel showing the function, does not.
#include <QList>
#include <QRectF>
#include <QWidget>

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/volume.hpp"

class TransferFunctionEditor final : public QWidget {
  Q_OBJECT

 public:
  static constexpr double kPointRadius = 5.0;  // circles, pixels
  static constexpr double kHitRadius = 8.0;    // how near a press must be to take a point, pixels
  static constexpr int kMargin = 8;            // around the plot: room for the circles at its edges
  static constexpr double kMinGap = 1e-4;      // smallest distance of neighbouring values, × the range
  static constexpr int kHistogramBins = 128;   // what the panel asks volumeHistogram for

  explicit TransferFunctionEditor(QWidget* parent = nullptr);

  // The function shown (ascending values, at least two points and low < high; anything else shows
  // an empty plot that takes no edits). Keeps the selection while the number of points is the same.
  void setPoints(const std::vector<mfr::TransferPoint>& points);
  [[nodiscard]] const std::vector<mfr::TransferPoint>& points() const { return points_; }
  // Sample counts in equal bins over [low, high] (empty: no histogram).
  void setHistogram(const std::vector<std::uint64_t>& counts);
  [[nodiscard]] const std::vector<std::uint64_t>& histogram() const { return histogram_; }

  // The selected point's index, -1 for none.
  Q_INVOKABLE int selectedPoint() const { return selected_; }
  void selectPoint(int index);

  // Edits under the mouse's rules; each emits edited() when it changed something.
  // A point at `value` strictly inside the range (kMinGap from its neighbours), colour interpolated
  // there, opacity clamped to 0 … 1; selected. Returns its index, or -1 when refused.
  int addPoint(double value, double opacity);
  // Value clamped between the neighbours (unchanged for the first and last point), opacity to 0 … 1.
  bool movePoint(int index, double value, double opacity);
  bool setPointColor(int index, const glm::vec3& rgb);  // channels clamped to 0 … 1
  // Any point but the first and the last.
  bool removePoint(int index);
  // A colour dialog (object name "hvPointColorDialog", window-modal, not blocking) for the point.
  void editPointColor(int index);

  // Value ↔ pixel mapping in this widget's coordinates. Invokable as well: the app tests reach them
  // through the meta-object, since the plugin is not linked into them.
  Q_INVOKABLE QRectF plotRect() const;
  Q_INVOKABLE double xForValue(double value) const;
  Q_INVOKABLE double valueForX(double x) const;
  Q_INVOKABLE double yForOpacity(double opacity) const;
  Q_INVOKABLE double opacityForY(double y) const;
  // The point whose circle is nearest `position` within kHitRadius, or -1.
  Q_INVOKABLE int pointAt(const QPointF& position) const;
  Q_INVOKABLE QList<quint64> histogramCounts() const;

  // Colour and opacity at `value`, linear between the points and clamped outside them, as
  // TransferFunction::table() interpolates them.
  [[nodiscard]] static glm::vec4 colorAt(const std::vector<mfr::TransferPoint>& points, double value);

  [[nodiscard]] QSize sizeHint() const override { return {280, 150}; }
  [[nodiscard]] QSize minimumSizeHint() const override { return {120, 90}; }

 signals:
  void edited();            // the user changed points()
  void selectionChanged();  // selectedPoint() changed

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;

 private:
  [[nodiscard]] bool editable() const;  // a function with a non-empty range is shown
  [[nodiscard]] double low() const { return points_.front().value; }
  [[nodiscard]] double high() const { return points_.back().value; }

  std::vector<mfr::TransferPoint> points_;
  std::vector<std::uint64_t> histogram_;
  int selected_ = -1;
  int dragged_ = -1;  // the point the left button holds
};
