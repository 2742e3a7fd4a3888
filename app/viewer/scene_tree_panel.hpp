#pragma once
// The scene dock: one row per object with a visibility check box, a colour swatch (click to
// change) and an editable opacity, then one row per volume (name, grid size, visibility).
#include <QWidget>

#include <cstddef>

#include "mfr/scene/volume.hpp"

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
  // A volume's row: its name (with the field read, for a file with several) and its grid size.
  static QString volumeText(const mfr::Volume& volume, std::size_t index);
  static QString gridText(const mfr::Volume& volume);
  void itemChanged(QTreeWidgetItem* item, int column);
  void itemClicked(QTreeWidgetItem* item, int column);

  ViewerModel& model_;
  QTreeWidget* tree_ = nullptr;
  bool rebuilding_ = false;
};
