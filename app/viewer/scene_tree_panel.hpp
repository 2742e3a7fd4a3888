#pragma once
// The scene dock: one row per object with a visibility check box, a colour swatch (click to
// change) and an editable opacity, then one row per volume (name, grid size, visibility). Above
// them, for a molecule file: its representations (spheres, ball and stick, sticks, surface); for
// parts with data arrays: Colour by (a field, or the parts' own colours), the colour map and the
// range mapped to its ends.
#include <QWidget>

#include <array>
#include <cstddef>

#include "mfr/scene/volume.hpp"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;
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
  void showFieldColoring();                 // the model's colouring in the Colour-by controls
  void applyFieldColoring(bool dataRange);  // the controls' colouring to the model

  void showMoleculeStyle();  // the model's molecule representations in the Molecule row

  ViewerModel& model_;
  QTreeWidget* tree_ = nullptr;
  QWidget* moleculeRow_ = nullptr;        // shown for a molecule file
  std::array<QCheckBox*, 5> molecule_{};  // spheres, ball-and-stick, sticks, cartoon, surface
  QWidget* fieldRow_ = nullptr;           // hidden when no part has a field
  QComboBox* colorBy_ = nullptr;
  QComboBox* colorMap_ = nullptr;
  QDoubleSpinBox* rangeLow_ = nullptr;
  QDoubleSpinBox* rangeHigh_ = nullptr;
  QPushButton* dataRange_ = nullptr;
  QLabel* fieldNote_ = nullptr;
  bool rebuilding_ = false;
};
