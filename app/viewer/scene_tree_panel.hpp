#pragma once
// The scene dock: one row per object with a visibility check box, a colour swatch (click to
// change) and an editable opacity, then one row per volume (name, grid size, visibility).
#include <QWidget>

class QTreeWidget;
class QTreeWidgetItem;
class ViewerModel;

class SceneTreePanel final : public QWidget {
  Q_OBJECT

 public:
  explicit SceneTreePanel(ViewerModel& model, QWidget* parent = nullptr);

 private:
  void rebuild();
  void showValues();
  void itemChanged(QTreeWidgetItem* item, int column);
  void itemClicked(QTreeWidgetItem* item, int column);

  ViewerModel& model_;
  QTreeWidget* tree_ = nullptr;
  bool rebuilding_ = false;
};
