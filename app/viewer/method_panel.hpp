#pragma once
// The method dock: every render method, the operation, and one widget per parameter generated
// from the method's ParamSpec list (Int → spin box, Float → double spin box, Bool → check box,
// Choice → combo box), so a new method needs no viewer code.
#include <QWidget>

#include <map>
#include <string>

class QComboBox;
class QFormLayout;
class QLabel;
class ViewerModel;

class MethodPanel final : public QWidget {
  Q_OBJECT

 public:
  explicit MethodPanel(ViewerModel& model, QWidget* parent = nullptr);

 private:
  void rebuildParameters();
  void showParameterValues();
  void syncMethodCombo();

  ViewerModel& model_;
  QComboBox* methodCombo_ = nullptr;
  QComboBox* operationCombo_ = nullptr;
  QLabel* description_ = nullptr;
  QWidget* paramsBox_ = nullptr;
  QFormLayout* paramsLayout_ = nullptr;
  std::map<std::string, QWidget*> editors_;  // by parameter name
};
