#pragma once
// The Probe dock: what lies behind one pixel. Ctrl + left click on the view probes the pixel under
// the cursor; the dock lists the oracle's exact sorted fragments there — distance from the eye,
// part, colour and opacity, facing, and each fragment's share of the pixel's colour ("over") —
// and, for a GPU method keeping sorted lists, which of them the method holds (a k-buffer's k
// nearest, a budget method's core). The probe follows the view: after each full frame (new
// camera, method, parameters or scene) the same point is probed again. Clear ends it.
#include <QPoint>
#include <QWidget>

#include <optional>

#include "viewer_model.hpp"

class QLabel;
class QPushButton;
class QTableWidget;
class RenderView;
struct ViewProbe;

class ProbePanel final : public QWidget {
  Q_OBJECT

 public:
  // Table columns.
  enum Column {
    Index,
    EyeDepth,
    Part,
    Colour,
    Alpha,
    Faces,
    Share,
    Held,
    HybridShare,
    VolumeShare,
    ZThicknessShare,
    FieldValue,
    ColumnCount
  };

  ProbePanel(ViewerModel& model, RenderView& view, QWidget* parent = nullptr);
  // Probes `point` of the view (logical coordinates) now and after every full frame until cleared.
  void probe(QPointF point);
  void clear();
  [[nodiscard]] std::optional<QPointF> point() const { return point_; }

 signals:
  void probed();  // the table shows a new probe (or its error)
  // A fragment's row double-clicked: the scene part it belongs to (an index of the scene's objects).
  void partChosen(int index);

 private:
  void refresh();
  void refreshIfChanged();  // after a full frame: again unless that pane's frame is the probed one
  void show(const ViewProbe& result);

  ViewerModel& model_;
  RenderView& view_;
  std::optional<QPointF> point_;
  int probedSide_ = 0;
  ImageKey probedKey_;  // the frame of probedSide_ when it was probed
  QLabel* summary_ = nullptr;
  QTableWidget* table_ = nullptr;
  QPushButton* clear_ = nullptr;
};
