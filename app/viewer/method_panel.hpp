#pragma once
// The method dock: every render method, the operation, and one widget per parameter generated
// from the method's ParamSpec list (Int → spin box, Float → double spin box, Bool → check box,
// Choice → combo box), so a new method needs no viewer code. With the operation zthickness a
// Thickness row appears (ViewerModel::zThickness, shared by both sides), with the operation volume
// ("auto" on a volume scene included) a Step row (ViewerModel::volumeStep, shared, and Default). One panel per side:
// side 0 edits the main method, side 1 the second method of compare mode (its widgets' object names carry a "B" suffix:
// methodComboB, param-k-B, …).
#include <QWidget>

#include <map>
#include <string>

class QComboBox;
class QDoubleSpinBox;
class QFormLayout;
class QLabel;
class ViewerModel;

class MethodPanel final : public QWidget {
  Q_OBJECT

 public:
  explicit MethodPanel(ViewerModel& model, int side = 0, QWidget* parent = nullptr);

 private:
  void rebuildParameters();
  void showParameterValues();
  void syncMethodCombo();
  void showThickness();
  void showStep();

  [[nodiscard]] QString objectName(const QString& base) const;

  ViewerModel& model_;
  int side_ = 0;
  QString shownMethod_;  // whose editors are built
  QComboBox* methodCombo_ = nullptr;
  QComboBox* operationCombo_ = nullptr;
  QDoubleSpinBox* thickness_ = nullptr;  // operation zthickness (ViewerModel::zThickness)
  QDoubleSpinBox* step_ = nullptr;       // operation volume (ViewerModel::volumeStep)
  QWidget* stepRow_ = nullptr;           // step_ and its Default button
  QFormLayout* topLayout_ = nullptr;
  QLabel* description_ = nullptr;
  QWidget* paramsBox_ = nullptr;
  QFormLayout* paramsLayout_ = nullptr;
  std::map<std::string, QWidget*> editors_;  // by parameter name
};
