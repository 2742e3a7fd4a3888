#pragma once
// The scene dock: one row per object with a visibility check box, a colour swatch (click to
// change) and an editable opacity, then one row per volume (name, grid size, visibility). Above
// them, for a molecule file: its representations (spheres, ball and stick, sticks, surface); for
// parts with data arrays: Colour by (a field, or the parts' own colours), the colour map and the
// range mapped to its ends. A filter by name above the rows, and several rows selected edited at
// once (context menu, Space): CAD assemblies have thousands of parts.
#include <QList>
#include <QWidget>

#include <array>
#include <cstddef>
#include <functional>

#include "mfr/scene/volume.hpp"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QAction;
class QLabel;
class QLineEdit;
class QPushButton;
class QTreeWidget;
class QTreeWidgetItem;
class QUndoStack;
class ViewerModel;

class SceneTreePanel final : public QWidget {
  Q_OBJECT

 public:
  explicit SceneTreePanel(ViewerModel& model, QWidget* parent = nullptr);
  // Selects the part's row alone, in sight (a filter that hides it is cleared); -1 clears the
  // selection. A part picked in the view or the Probe dock.
  void selectPart(int index);
  // The edits of parts made in this dock (visibility, colour, opacity; one step per action), for
  // Edit ▸ Undo and Redo. A new scene, parts added or removed, or another colouring by a field
  // clears it (its steps name parts by index, and colours of the field before).
  [[nodiscard]] QUndoStack* undoStack() const { return undo_; }

 private:
  // Runs `edit` of `parts` and records it as one undoable step named `text`: the parts' looks
  // before and after (nothing when it changed nothing).
  void recordEdit(const QString& text, const QList<int>& parts, const std::function<void()>& edit);
  [[nodiscard]] QList<int> allParts() const;
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

  // The filter: rows whose name does not match are hidden (not the parts they stand for).
  void applyFilter();
  // The parts of the selected rows that the filter shows, in row order (volume rows left out).
  [[nodiscard]] QList<int> selectedParts() const;
  [[nodiscard]] QString partsText(const QList<int>& parts) const;  // a part's name, or "n parts"
  void updateSelectionActions();
  void setSelectedVisible(bool visible);
  void toggleSelectedVisible();
  void showOnlySelected();
  void chooseSelectedColour();
  void chooseSelectedOpacity();
  void fitViewToSelected();

  ViewerModel& model_;
  QTreeWidget* tree_ = nullptr;
  QLineEdit* filter_ = nullptr;
  QLabel* filterCount_ = nullptr;
  // On the selection: show, hide, toggle (Space), show only, show all, fit the view, colour,
  // opacity, reset colour. Members, so that their shortcuts work and tests can trigger them.
  QAction* showParts_ = nullptr;
  QAction* hideParts_ = nullptr;
  QAction* toggleParts_ = nullptr;
  QAction* showOnlyParts_ = nullptr;
  QAction* showAllParts_ = nullptr;
  QAction* fitParts_ = nullptr;
  QAction* colourParts_ = nullptr;
  QAction* opacityParts_ = nullptr;
  QAction* resetColourParts_ = nullptr;
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
  quint64 rowsBuilt_ = 0;  // rebuilds so far: a dialog open across one edits no part
  QUndoStack* undo_ = nullptr;
};
