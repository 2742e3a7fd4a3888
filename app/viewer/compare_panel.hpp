#pragma once
// The compare dock: turns compare mode on, picks the layout (side by side or split) and what the
// panes show (images or heat maps of their error), lists RMSE and FLIP of both methods against
// the exact image, and holds the second method's generated panel (MethodPanel, side 1).
#include <QWidget>

class QCheckBox;
class QComboBox;
class QSlider;
class QTableWidget;
class ViewerModel;

class ComparePanel final : public QWidget {
  Q_OBJECT

 public:
  explicit ComparePanel(ViewerModel& model, QWidget* parent = nullptr);

 private:
  void showSettings();
  void showMetrics();

  ViewerModel& model_;
  QCheckBox* enabled_ = nullptr;
  QComboBox* layout_ = nullptr;
  QSlider* split_ = nullptr;
  QComboBox* display_ = nullptr;
  QTableWidget* metrics_ = nullptr;
};
