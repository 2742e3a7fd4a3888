#include "scene_tree_panel.hpp"

#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QGuiApplication>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QPixmap>
#include <QPushButton>
#include <QRegularExpression>
#include <QStyledItemDelegate>
#include <QTimer>
#include <QTreeWidget>
#include <QUndoStack>
#include <QVBoxLayout>

#include <QSignalBlocker>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "header_sizing.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/measure.hpp"
#include "viewer_model.hpp"

namespace {

// One step of the Scene dock's history: the looks of the parts an action changed, before and after.
// Undo and redo put back only what the step changed — visibility, the colour (with the file's
// vertex colours and a field colouring) and the opacity, each on its own — over the parts as they
// are now: edits made since by others (the ghosting panel's opacities) stay. Putting back whole
// looks undid those too, and undoing a colour reset the opacity (review 28).
class PartsEdit final : public QUndoCommand {
 public:
  PartsEdit(ViewerModel& model, const QString& text, std::vector<ViewerModel::PartLook> before,
            std::vector<ViewerModel::PartLook> after)
      : QUndoCommand(text), model_(model), before_(std::move(before)), after_(std::move(after)) {}
  void undo() override { apply(after_, before_); }
  void redo() override { apply(before_, after_); }  // on push: the edit was made, nothing changes

 private:
  void apply(const std::vector<ViewerModel::PartLook>& from, const std::vector<ViewerModel::PartLook>& to) {
    QList<int> parts;
    for (const ViewerModel::PartLook& look : to) parts.push_back(look.index);
    std::vector<ViewerModel::PartLook> now = model_.partLooks(parts);
    if (now.size() != to.size()) return;  // parts gone: a new scene clears the history first
    for (std::size_t i = 0; i < to.size(); ++i) {
      mfr::Material& material = now[i].material;
      const mfr::Material &a = from[i].material, &b = to[i].material;
      if (from[i].visible != to[i].visible) now[i].visible = to[i].visible;
      if (glm::vec3(a.color) != glm::vec3(b.color) || a.vertexColors != b.vertexColors ||
          a.fieldColors != b.fieldColors) {
        material.color = glm::vec4(glm::vec3(b.color), material.color.a);
        material.vertexColors = b.vertexColors;
        material.fieldColors = b.fieldColors;
      }
      if (a.color.a != b.color.a) material.color.a = b.color.a;
    }
    model_.setPartLooks(now);
  }

  ViewerModel& model_;
  std::vector<ViewerModel::PartLook> before_, after_;
};

}  // namespace

namespace {

enum Column { kName = 0, kColour = 1, kOpacity = 2, kTriangles = 3 };

// The Opacity column's editor: 0 … 1 with the column's three decimals. Qt's default editor for a
// double has two, so opening it and pressing Enter turned 0.125 into 0.13 and 0.004 into 0 (the
// part vanished), and three decimals could not be typed (a bug hunt).
class OpacityDelegate : public QStyledItemDelegate {
 public:
  using QStyledItemDelegate::QStyledItemDelegate;
  QWidget* createEditor(QWidget* parent, const QStyleOptionViewItem&, const QModelIndex&) const override {
    auto* box = new QDoubleSpinBox(parent);
    box->setObjectName(QStringLiteral("opacityEditor"));
    box->setFrame(false);
    box->setRange(0.0, 1.0);
    box->setDecimals(3);
    box->setSingleStep(0.05);
    return box;
  }
};

// The other columns take no editor: the name cell's text editor renamed the row, not the part, and
// a rebuild brought the name back.
class ReadOnlyDelegate : public QStyledItemDelegate {
 public:
  using QStyledItemDelegate::QStyledItemDelegate;
  QWidget* createEditor(QWidget*, const QStyleOptionViewItem&, const QModelIndex&) const override { return nullptr; }
};

// The filter's text: a name matches when it contains the text; with * (any characters) or ? (one)
// the pattern must match the whole name, as a shell's. Case is ignored. Not Qt's fromWildcard:
// its * stops at a '/', and assembly parts are named with paths.
QRegularExpression filterPattern(const QString& text) {
  const bool wildcard = text.contains(QLatin1Char('*')) || text.contains(QLatin1Char('?'));
  QString pattern;
  for (const QChar c : text)
    pattern += c == QLatin1Char('*')   ? QStringLiteral(".*")
               : c == QLatin1Char('?') ? QStringLiteral(".")
                                       : QRegularExpression::escape(QString(c));
  if (wildcard) pattern = QRegularExpression::anchoredPattern(pattern);
  return QRegularExpression(pattern,
                            QRegularExpression::CaseInsensitiveOption | QRegularExpression::DotMatchesEverythingOption);
}

QColor colourOf(const mfr::Object& o) {
  return QColor::fromRgbF(o.material.color.r, o.material.color.g, o.material.color.b);
}

// The colour column's text: the colour's name, or "file colours" while the mesh's per-vertex colours
// show (multiplied by the swatch's colour, white for molecules).
QString colourText(const mfr::Object& o) {
  if (o.material.fieldColors) return QString::fromStdString(o.material.fieldColors->field);
  const bool perVertex = o.material.vertexColors && o.mesh && !o.mesh->colors.empty();
  return perVertex ? QObject::tr("file colours") : colourOf(o).name();
}

// A part's row. Its Triangles cell's tooltip measures the part's surface in the world
// (mfr::measureSurface, as mfr info prints it) the first time it is asked for, not at every rebuild:
// a CT's surfaces take a fraction of a second each. With a section plane it measures the part as
// drawn — a capped solid's kept volume and cross-section, as mfr info --section — and the whole
// part below; measured again after an edit (the cut may have changed).
class PartItem final : public QTreeWidgetItem {
 public:
  PartItem(const ViewerModel& model, int index) : model_(model), index_(index) {}
  [[nodiscard]] QVariant data(int column, int role) const override {
    if (column != kTriangles || role != Qt::ToolTipRole) return QTreeWidgetItem::data(column, role);
    const auto i = static_cast<std::size_t>(index_);
    const auto& objects = model_.scene().objects;
    if (index_ < 0 || i >= objects.size() || !objects[i].mesh) return {};
    const mfr::Object& whole = objects[i];
    const mfr::SectionReport& report = model_.sectionReport();
    const mfr::Scene& drawn = model_.drawnScene();
    const bool sectioned = &drawn != &model_.scene() && i < report.outcomes.size() && i < drawn.objects.size();
    const mfr::SectionOutcome outcome = sectioned ? report.outcomes[i] : mfr::SectionOutcome::kKept;
    const mfr::Mesh* shown = sectioned ? drawn.objects[i].mesh.get() : whole.mesh.get();
    // The model's revision: every edit (a section moved included) makes a new cut.
    if (measured_.isEmpty() || measuredRevision_ != model_.sceneRevision()) {
      const std::string wholeText = mfr::describeSurface(mfr::measureSurface(*whole.mesh, whole.transform));
      if (outcome == mfr::SectionOutcome::kKept)
        measured_ = QString::fromStdString(wholeText);
      else if (outcome == mfr::SectionOutcome::kRemoved)
        measured_ = QString::fromStdString(mfr::describeCut(outcome, 0.0) + "\nwhole part: " + wholeText);
      else
        measured_ =
            QString::fromStdString(mfr::describeSurface(mfr::measureSurface(*shown, drawn.objects[i].transform)) +
                                   mfr::describeCut(outcome, report.capAreas[i]) + "\nwhole part: " + wholeText);
      measuredRevision_ = model_.sceneRevision();
    }
    return measured_;
  }

 private:
  const ViewerModel& model_;
  int index_;
  mutable QString measured_;
  mutable quint64 measuredRevision_ = 0;
};

QIcon swatch(const QColor& colour) {
  QPixmap pixmap(16, 16);
  pixmap.fill(colour);
  return QIcon(pixmap);
}

// The Molecule row's check boxes, in order.
constexpr std::array<mfr::MoleculeParts mfr::MoleculeStyle::*, 5> kMoleculeRepresentations = {
    &mfr::MoleculeStyle::spheres, &mfr::MoleculeStyle::ballAndStick, &mfr::MoleculeStyle::sticks,
    &mfr::MoleculeStyle::cartoon, &mfr::MoleculeStyle::surface};

}  // namespace

SceneTreePanel::SceneTreePanel(ViewerModel& model, QWidget* parent) : QWidget(parent), model_(model) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  // A molecule's representations (PyMOL's show): any combination, the file re-read with them.
  moleculeRow_ = new QWidget;
  moleculeRow_->setObjectName(QStringLiteral("moleculeRow"));
  // Two rows of boxes, so that the row does not set the dock's width.
  auto* molecule = new QGridLayout(moleculeRow_);
  molecule->setContentsMargins(4, 4, 4, 0);
  molecule->addWidget(new QLabel(tr("Molecule")), 0, 0);
  const std::array<std::pair<const char*, QString>, 5> representations = {
      std::pair{"moleculeSpheres", tr("Spheres")}, std::pair{"moleculeBallAndStick", tr("Ball and stick")},
      std::pair{"moleculeSticks", tr("Sticks")}, std::pair{"moleculeCartoon", tr("Cartoon")},
      std::pair{"moleculeSurface", tr("Surface")}};
  for (std::size_t i = 0; i < molecule_.size(); ++i) {
    molecule_[i] = new QCheckBox(representations[i].second);
    molecule_[i]->setObjectName(QString::fromLatin1(representations[i].first));
    molecule->addWidget(molecule_[i], static_cast<int>(i / 3), static_cast<int>(i % 3) + 1);
    // Checked: the representation on every part; unchecked: on none. A representation the style
    // draws on some parts only (sticks@ligands) shows partly checked, and a click makes it all.
    connect(molecule_[i], &QCheckBox::stateChanged, this, [this](int state) {
      const std::optional<mfr::MoleculeStyle> loaded = model_.moleculeStyle();
      if (!loaded || state == Qt::PartiallyChecked) return;
      // From all the boxes, so that quick clicks add up while the file is read again.
      mfr::MoleculeStyle style = *loaded;
      for (std::size_t k = 0; k < molecule_.size(); ++k)
        if (molecule_[k]->checkState() != Qt::PartiallyChecked)
          style.*kMoleculeRepresentations[k] =
              molecule_[k]->checkState() == Qt::Checked ? mfr::MoleculeParts::all() : mfr::MoleculeParts{};
      if (!style.any()) {
        showMoleculeStyle();  // one at least
        return;
      }
      if (!model_.setMoleculeStyle(style)) showMoleculeStyle();  // refused while another file is read
    });
  }
  molecule_[0]->setToolTip(tr("Van der Waals spheres (space-filling, CPK)"));
  molecule_[1]->setToolTip(tr("Balls of 23 % of the van der Waals radius and sticks of 0.15 Å (Jmol's)"));
  molecule_[2]->setToolTip(tr("Bonds as sticks of 0.25 Å (PyMOL's); bonds found from distances as Open Babel does"));
  molecule_[3]->setToolTip(
      tr("Each chain's backbone: helices, strands with arrows and loops, coloured red, yellow "
         "and green (PyMOL's cartoon); from the file's HELIX/SHEET records, or DSSP"));
  molecule_[4]->setToolTip(tr("The solvent-excluded surface of each chain and of the ligands (probe 1.4 Å)"));
  molecule->setColumnStretch(4, 1);
  moleculeRow_->setVisible(false);
  layout->addWidget(moleculeRow_);
  // Colour by a field (mfr::colorObjectsByField): ParaView's "Color by", map and range.
  fieldRow_ = new QWidget;
  auto* fields = new QGridLayout(fieldRow_);
  fields->setContentsMargins(4, 4, 4, 0);
  colorBy_ = new QComboBox;
  colorBy_->setObjectName(QStringLiteral("colorByField"));
  colorBy_->setToolTip(tr("Colour every part that has this point-data or cell-data array by it"));
  colorMap_ = new QComboBox;
  colorMap_->setObjectName(QStringLiteral("colorByMap"));
  for (const std::string& name : mfr::colorMapNames()) colorMap_->addItem(QString::fromStdString(name));
  rangeLow_ = new QDoubleSpinBox;
  rangeHigh_ = new QDoubleSpinBox;
  rangeLow_->setObjectName(QStringLiteral("colorRangeLow"));
  rangeHigh_->setObjectName(QStringLiteral("colorRangeHigh"));
  for (QDoubleSpinBox* box : {rangeLow_, rangeHigh_}) {
    box->setRange(-1e30, 1e30);
    box->setDecimals(6);
    box->setKeyboardTracking(false);
    box->setToolTip(tr("The values at the ends of the colour map (values outside get the end colours)"));
  }
  dataRange_ = new QPushButton(tr("Data Range"));
  dataRange_->setObjectName(QStringLiteral("colorRangeReset"));
  dataRange_->setToolTip(tr("Map the field's smallest and largest value (over every part that has it) to the ends"));
  fieldNote_ = new QLabel;
  fieldNote_->setObjectName(QStringLiteral("colorByNote"));
  fieldNote_->setWordWrap(true);
  // Three columns at most, so that the rows do not set the dock's width.
  fields->addWidget(new QLabel(tr("Colour by")), 0, 0);
  fields->addWidget(colorBy_, 0, 1);
  fields->addWidget(colorMap_, 0, 2);
  fields->addWidget(new QLabel(tr("Range")), 1, 0);
  fields->addWidget(rangeLow_, 1, 1);
  fields->addWidget(rangeHigh_, 1, 2);
  fields->addWidget(dataRange_, 2, 2);
  fields->addWidget(fieldNote_, 3, 0, 1, 3);
  fields->setColumnStretch(1, 1);
  fields->setColumnStretch(2, 1);
  layout->addWidget(fieldRow_);
  connect(colorBy_, &QComboBox::activated, this, [this] { applyFieldColoring(true); });
  connect(colorMap_, &QComboBox::activated, this, [this] { applyFieldColoring(false); });
  connect(rangeLow_, &QDoubleSpinBox::valueChanged, this, [this] { applyFieldColoring(false); });
  connect(rangeHigh_, &QDoubleSpinBox::valueChanged, this, [this] { applyFieldColoring(false); });
  connect(dataRange_, &QPushButton::clicked, this, [this] { applyFieldColoring(true); });
  auto* filterRow = new QHBoxLayout;
  filterRow->setContentsMargins(4, 4, 4, 0);
  filter_ = new QLineEdit;
  filter_->setObjectName(QStringLiteral("sceneFilter"));
  filter_->setPlaceholderText(tr("Filter by name (* and ? as wildcards)"));
  filter_->setClearButtonEnabled(true);
  filter_->setToolTip(
      tr("Rows whose name contains the text (case ignored); with * or ? the pattern matches the "
         "whole name. Only the rows are hidden: the parts stay as they are drawn"));
  filterCount_ = new QLabel;
  filterCount_->setObjectName(QStringLiteral("sceneFilterCount"));
  filterRow->addWidget(filter_, 1);
  filterRow->addWidget(filterCount_);
  layout->addLayout(filterRow);
  connect(filter_, &QLineEdit::textChanged, this, &SceneTreePanel::applyFilter);
  tree_ = new QTreeWidget;
  tree_->setObjectName(QStringLiteral("sceneTree"));
  tree_->setColumnCount(4);
  tree_->setHeaderLabels({tr("Object"), tr("Colour"), tr("Opacity"), tr("Triangles")});
  tree_->setRootIsDecorated(false);
  tree_->setUniformRowHeights(true);  // CAD assemblies have thousands of parts
  tree_->header()->setStretchLastSection(false);
  tree_->header()->setSectionResizeMode(kName, QHeaderView::Stretch);
  for (int c : {kColour, kOpacity, kTriangles}) tree_->header()->setSectionResizeMode(c, QHeaderView::ResizeToContents);
  tree_->setEditTriggers(QAbstractItemView::DoubleClicked | QAbstractItemView::EditKeyPressed);
  tree_->setSelectionMode(QAbstractItemView::ExtendedSelection);
  tree_->setItemDelegateForColumn(kOpacity, new OpacityDelegate(tree_));
  for (int c : {kName, kColour, kTriangles}) tree_->setItemDelegateForColumn(c, new ReadOnlyDelegate(tree_));
  layout->addWidget(tree_);
  undo_ = new QUndoStack(this);
  undo_->setUndoLimit(50);  // a step of 16,000 parts holds each one's material twice
  connect(tree_, &QTreeWidget::itemChanged, this, &SceneTreePanel::itemChanged);
  connect(tree_, &QTreeWidget::itemClicked, this, &SceneTreePanel::itemClicked);
  // The selection's actions: in the context menu, with shortcuts while the tree has the focus
  // (Space toggles, as FreeCAD's tree does). Right-click selects the row under the cursor first
  // (Qt's views do) unless it is selected already, so the menu acts on what is selected.
  const auto addAction = [this](const char* name, const QString& text, auto slot) {
    auto* action = new QAction(text, this);
    action->setObjectName(QString::fromLatin1(name));
    action->setShortcutContext(Qt::WidgetWithChildrenShortcut);
    connect(action, &QAction::triggered, this, slot);
    tree_->addAction(action);
    return action;
  };
  showParts_ = addAction("showPartsAction", tr("Show"), [this] { setSelectedVisible(true); });
  hideParts_ = addAction("hidePartsAction", tr("Hide"), [this] { setSelectedVisible(false); });
  toggleParts_ = addAction("togglePartsAction", tr("Toggle Visibility"), &SceneTreePanel::toggleSelectedVisible);
  toggleParts_->setShortcut(QKeySequence(Qt::Key_Space));
  showOnlyParts_ = addAction("showOnlyPartsAction", tr("Show Only These"), &SceneTreePanel::showOnlySelected);
  showAllParts_ = addAction("showAllPartsAction", tr("Show All Parts"), [this] {
    const QList<int> parts = allParts();
    recordEdit(tr("Show All Parts"), parts, [&] {
      QMap<int, bool> visible;
      for (const int i : parts) visible.insert(i, true);
      model_.setObjectVisibilities(visible);
    });
  });
  fitParts_ = addAction("fitPartsAction", tr("Fit View to These"), &SceneTreePanel::fitViewToSelected);
  colourParts_ = addAction("colourPartsAction", tr("Colour…"), &SceneTreePanel::chooseSelectedColour);
  opacityParts_ = addAction("opacityPartsAction", tr("Opacity…"), &SceneTreePanel::chooseSelectedOpacity);
  resetColourParts_ = addAction("resetColourAction", tr("Reset Colour to the File's"), [this] {
    const QList<int> parts = selectedParts();
    if (parts.isEmpty()) return;
    recordEdit(tr("Reset Colour of %1").arg(partsText(parts)), parts, [&] { model_.resetObjectColors(parts); });
  });
  tree_->setContextMenuPolicy(Qt::CustomContextMenu);
  connect(tree_, &QWidget::customContextMenuRequested, this, [this](const QPoint& at) {
    updateSelectionActions();
    if (model_.scene().objects.empty()) return;
    QMenu menu(this);  // also on empty space or a volume row: Show All Parts needs no selection
    menu.addActions({showParts_, hideParts_, toggleParts_, showOnlyParts_, showAllParts_});
    menu.addSeparator();
    menu.addAction(fitParts_);
    menu.addSeparator();
    menu.addActions({colourParts_, opacityParts_, resetColourParts_});
    menu.exec(tree_->viewport()->mapToGlobal(at));
  });
  connect(tree_, &QTreeWidget::itemSelectionChanged, this, &SceneTreePanel::updateSelectionActions);
  connect(&model_, &ViewerModel::sceneChanged, this, &SceneTreePanel::updateSelectionActions);
  updateSelectionActions();
  connect(&model_, &ViewerModel::sceneLoaded, this, &SceneTreePanel::rebuild);
  connect(&model_, &ViewerModel::sceneLoaded, this, &SceneTreePanel::showMoleculeStyle);
  // A re-read that fails or is cancelled leaves the representations drawn: the boxes show them.
  connect(&model_, &ViewerModel::loadFailed, this, &SceneTreePanel::showMoleculeStyle);
  connect(&model_, &ViewerModel::loadCancelled, this, &SceneTreePanel::showMoleculeStyle);
  connect(&model_, &ViewerModel::partsChanged, this, &SceneTreePanel::rebuild);  // isosurfaces added or removed
  // Edits from elsewhere (a session's overrides, plugins) show up in the rows.
  connect(&model_, &ViewerModel::sceneChanged, this, &SceneTreePanel::showValues);
}

namespace {
// Volume rows follow the object rows; their UserRole is -1 - the volume's index.
int volumeOfRow(const QTreeWidgetItem* item) {
  const int index = item->data(kName, Qt::UserRole).toInt();
  return index < 0 ? -1 - index : -1;
}
}  // namespace

QString SceneTreePanel::volumeText(const mfr::Volume& volume, std::size_t index) {
  // The field read, when the file has several to choose from (the Volume panel's Field).
  const QString field =
      volume.fields.size() > 1 ? QStringLiteral(" [%1]").arg(QString::fromStdString(volume.field)) : QString();
  return tr("%1%2 (volume)")
      .arg(QString::fromStdString(volume.name.empty() ? "volume " + std::to_string(index) : volume.name), field);
}

QString SceneTreePanel::gridText(const mfr::Volume& volume) {
  const glm::ivec3 d = volume.grid ? volume.grid->dims : glm::ivec3(0);
  return QStringLiteral("%1×%2×%3").arg(d.x).arg(d.y).arg(d.z);
}

void SceneTreePanel::showMoleculeStyle() {
  const std::optional<mfr::MoleculeStyle> style = model_.moleculeStyle();
  moleculeRow_->setVisible(style.has_value());
  if (!style) return;
  for (std::size_t i = 0; i < molecule_.size(); ++i) {
    const QSignalBlocker block(molecule_[i]);
    const mfr::MoleculeParts& parts = (*style).*kMoleculeRepresentations[i];
    const bool some = static_cast<bool>(parts) && parts != mfr::MoleculeParts::all();
    molecule_[i]->setTristate(some);
    molecule_[i]->setCheckState(some ? Qt::PartiallyChecked : parts ? Qt::Checked : Qt::Unchecked);
  }
}

void SceneTreePanel::showFieldColoring() {
  const QStringList fields = model_.surfaceFields();
  fieldRow_->setVisible(!fields.isEmpty());
  const std::optional<mfr::FieldColors> shown = model_.fieldColoring();
  const QSignalBlocker blockField(colorBy_), blockMap(colorMap_), blockLow(rangeLow_), blockHigh(rangeHigh_);
  if (colorBy_->count() != fields.size() + 1) {
    colorBy_->clear();
    colorBy_->addItem(tr("Part colours"), QString());
    for (const QString& f : fields) colorBy_->addItem(f, f);
  }
  colorBy_->setCurrentIndex(shown ? std::max(0, colorBy_->findData(QString::fromStdString(shown->field))) : 0);
  if (shown) {
    // About four significant digits of the data range's span: 5.00 for B-factors (a span of 80).
    const glm::dvec2 values = model_.fieldDataRange(QString::fromStdString(shown->field));
    const double span = std::max(std::abs(values.y - values.x), 1e-30);
    const int decimals = std::clamp(3 - static_cast<int>(std::floor(std::log10(span))), 0, 12);
    rangeLow_->setDecimals(decimals);
    rangeHigh_->setDecimals(decimals);
    colorMap_->setCurrentText(QString::fromStdString(shown->map));
    rangeLow_->setValue(shown->range.x);
    rangeHigh_->setValue(shown->range.y);
  } else {
    // Nothing coloured: no range of an earlier colouring (another file's B-factors stayed in the
    // greyed boxes; a bug hunt). Choosing a field starts from its data range.
    for (QDoubleSpinBox* box : {rangeLow_, rangeHigh_}) {
      box->setDecimals(6);
      box->setValue(0.0);
    }
  }
  for (QWidget* w : std::initializer_list<QWidget*>{colorMap_, rangeLow_, rangeHigh_, dataRange_})
    w->setEnabled(shown.has_value());
  fieldNote_->setText(model_.fieldColoringError());
  fieldNote_->setVisible(!model_.fieldColoringError().isEmpty());
}

void SceneTreePanel::applyFieldColoring(bool dataRange) {
  const QString field = colorBy_->currentData().toString();
  std::optional<glm::dvec2> range;
  if (!dataRange && !field.isEmpty()) range = glm::dvec2(rangeLow_->value(), rangeHigh_->value());
  // The colouring shown asked for again (Data Range over the data's range, the same field picked
  // again) changes nothing: laid on anew, it took back colours chosen for parts, and the history
  // with them (hunt 33).
  const std::optional<mfr::FieldColors> shown = model_.fieldColoring();
  if (shown && !field.isEmpty() && shown->field == field.toStdString() &&
      shown->map == colorMap_->currentText().toStdString() &&
      shown->range == (range ? *range : model_.fieldDataRange(field)) && !model_.fieldColoringsAsLoaded()) {
    showFieldColoring();
    return;
  }
  // A refusal changes nothing either: the history stays.
  if (model_.setFieldColoring(field, colorMap_->currentText(), range))
    undo_->clear();     // the steps' materials name the colouring before
  showFieldColoring();  // the range picked, or the refusal
}

void SceneTreePanel::showValues() {
  showFieldColoring();
  const auto& objects = model_.scene().objects;
  const auto& volumes = model_.scene().volumes;
  if (tree_->topLevelItemCount() != static_cast<int>(objects.size() + volumes.size())) return;
  const QSignalBlocker block(tree_);
  // Held from the first row that changes (ghosting changes every row), not at every edit: giving
  // the sections back measures every column again, a few ms per edit at 4,000 parts (a review).
  std::optional<ContentSizedSectionsHeld> held;
  const auto changing = [&] {
    if (!held) held.emplace(tree_->header());
  };
  const auto setCheck = [&](QTreeWidgetItem* item, bool checked) {
    const Qt::CheckState state = checked ? Qt::Checked : Qt::Unchecked;
    if (item->checkState(kName) == state) return;
    changing();
    item->setCheckState(kName, state);
  };
  const auto setText = [&](QTreeWidgetItem* item, int column, const QString& text) {
    if (item->text(column) == text) return;
    changing();
    item->setText(column, text);
  };
  for (std::size_t v = 0; v < volumes.size(); ++v) {
    QTreeWidgetItem* item = tree_->topLevelItem(static_cast<int>(objects.size() + v));
    setCheck(item, volumes[v].visible);
    // Another field read (the Volume panel's Field): its name and grid.
    setText(item, kName, volumeText(volumes[v], v));
    setText(item, kColour, gridText(volumes[v]));
  }
  for (int i = 0; i < static_cast<int>(objects.size()); ++i) {
    QTreeWidgetItem* item = tree_->topLevelItem(i);
    const mfr::Object& o = objects[static_cast<std::size_t>(i)];
    setCheck(item, o.visible);
    if (item->text(kColour) != colourText(o) || item->data(kColour, Qt::UserRole).value<QColor>() != colourOf(o)) {
      changing();
      item->setIcon(kColour, swatch(colourOf(o)));
      item->setText(kColour, colourText(o));
      item->setData(kColour, Qt::UserRole, colourOf(o));
    }
    const double opacity = std::round(o.material.color.a * 1000.0) / 1000.0;
    if (item->data(kOpacity, Qt::EditRole) != QVariant(opacity)) {
      changing();
      item->setData(kOpacity, Qt::EditRole, opacity);
    }
  }
}

void SceneTreePanel::rebuild() {
  ++rowsBuilt_;
  undo_->clear();  // the steps name parts by index
  rebuilding_ = true;
  colorBy_->clear();  // another scene: its own fields
  showFieldColoring();
  tree_->clear();
  const auto& objects = model_.scene().objects;
  QList<QTreeWidgetItem*> items;
  items.reserve(static_cast<qsizetype>(objects.size()));
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const mfr::Object& o = objects[i];
    auto* item = new PartItem(model_, static_cast<int>(i));
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsUserCheckable | Qt::ItemIsEditable);
    item->setText(kName, QString::fromStdString(o.name.empty() ? "object " + std::to_string(i) : o.name));
    item->setData(kName, Qt::UserRole, static_cast<int>(i));
    item->setCheckState(kName, o.visible ? Qt::Checked : Qt::Unchecked);
    item->setIcon(kColour, swatch(colourOf(o)));
    item->setText(kColour, colourText(o));
    item->setData(kColour, Qt::UserRole, colourOf(o));
    item->setToolTip(kColour, tr("Click to change the colour (a chosen colour replaces the file's colours; "
                                 "right-click to go back to them)"));
    item->setData(kOpacity, Qt::EditRole, std::round(o.material.color.a * 1000.0) / 1000.0);
    item->setToolTip(kOpacity, tr("Double-click to edit (0 = invisible, 1 = opaque)"));
    item->setText(kTriangles, QString::number(o.mesh ? o.mesh->triangleCount() : 0));
    item->setTextAlignment(kTriangles, Qt::AlignRight | Qt::AlignVCenter);
    items.push_back(item);
  }
  // The scene's volumes (operation volume): name, grid size, visibility (at most 4 show).
  const auto& volumes = model_.scene().volumes;
  for (std::size_t v = 0; v < volumes.size(); ++v) {
    const mfr::Volume& volume = volumes[v];
    auto* item = new QTreeWidgetItem;
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsUserCheckable);
    item->setText(kName, volumeText(volume, v));
    item->setData(kName, Qt::UserRole, -1 - static_cast<int>(v));
    item->setCheckState(kName, volume.visible ? Qt::Checked : Qt::Unchecked);
    item->setText(kColour, gridText(volume));
    item->setToolTip(kName, tr("Drawn by the operation volume, mixed with the scene's other visible volumes where they "
                               "overlap (at most 4 at once)"));
    items.push_back(item);
  }
  tree_->addTopLevelItems(items);
  applyFilter();  // the filter typed stays for the next scene
  rebuilding_ = false;
  updateSelectionActions();
}

void SceneTreePanel::itemChanged(QTreeWidgetItem* item, int column) {
  if (rebuilding_) return;
  if (const int volume = volumeOfRow(item); volume >= 0) {
    if (column == kName) model_.setVolumeVisibleAt(volume, item->checkState(kName) == Qt::Checked);
    return;
  }
  const int index = item->data(kName, Qt::UserRole).toInt();
  if (column == kName) {
    const bool visible = item->checkState(kName) == Qt::Checked;
    recordEdit((visible ? tr("Show %1") : tr("Hide %1")).arg(partsText({index})), {index},
               [&] { model_.setObjectVisible(index, visible); });
  } else if (column == kOpacity) {
    const double opacity = std::clamp(item->data(kOpacity, Qt::EditRole).toDouble(), 0.0, 1.0);
    recordEdit(tr("Opacity of %1").arg(partsText({index})), {index}, [&] { model_.setObjectOpacity(index, opacity); });
    showValues();  // the clamped value, also when it was the part's opacity already (no sceneChanged)
  }
}

void SceneTreePanel::itemClicked(QTreeWidgetItem* item, int column) {
  // Not a Ctrl or Shift click, which adds to the selection.
  if (column != kColour || volumeOfRow(item) >= 0 || QGuiApplication::keyboardModifiers() != Qt::NoModifier) return;
  const int index = item->data(kName, Qt::UserRole).toInt();
  const QColor initial = colourOf(model_.scene().objects[static_cast<std::size_t>(index)]);
  const QString title = tr("Colour of %1").arg(item->text(kName));
  // After the click's own handling: the dialog's event loop may see a load end and the rows
  // rebuilt, which inside the click left the tree drawing the old scene's rows (a bug hunt). The
  // rows the click was on are those of now: a load's end already queued rebuilds them first.
  QTimer::singleShot(0, this, [this, index, initial, title, rows = rowsBuilt_] {
    if (rows != rowsBuilt_) return;
    const QColor chosen = QColorDialog::getColor(initial, this, title);
    // Another scene, or other parts, meanwhile: the index names another part (it recoloured the
    // new scene's part of that index).
    if (chosen.isValid() && rows == rowsBuilt_)
      recordEdit(tr("Colour of %1").arg(partsText({index})), {index}, [&] { model_.setObjectColor(index, chosen); });
  });
}

void SceneTreePanel::applyFilter() {
  const QString text = filter_->text().trimmed();
  const QRegularExpression pattern = filterPattern(text);
  const int rows = tree_->topLevelItemCount();
  int shown = 0;
  {
    const ContentSizedSectionsHeld held(tree_->header());  // rows of thousands of parts
    for (int r = 0; r < rows; ++r) {
      QTreeWidgetItem* item = tree_->topLevelItem(r);
      const bool match = text.isEmpty() || pattern.match(item->text(kName)).hasMatch();
      item->setHidden(!match);
      shown += match ? 1 : 0;
    }
  }
  filterCount_->setText(text.isEmpty() ? QString() : tr("%1 of %2").arg(shown).arg(rows));
  filterCount_->setVisible(!text.isEmpty());
  updateSelectionActions();
}

QList<int> SceneTreePanel::selectedParts() const {
  QList<int> parts;
  for (const QTreeWidgetItem* item : tree_->selectedItems())
    // Not the rows the filter hides (Select All selects them too: "filter, select all, hide" must
    // hide only what the filter shows).
    if (!item->isHidden() && volumeOfRow(item) < 0) parts.push_back(item->data(kName, Qt::UserRole).toInt());
  std::sort(parts.begin(), parts.end());
  return parts;
}

void SceneTreePanel::updateSelectionActions() {
  const QList<int> parts = selectedParts();
  for (QAction* action : {showParts_, hideParts_, toggleParts_, showOnlyParts_, fitParts_, colourParts_, opacityParts_})
    action->setEnabled(!parts.isEmpty());
  showAllParts_->setEnabled(!model_.scene().objects.empty());
  resetColourParts_->setEnabled(
      std::any_of(parts.begin(), parts.end(), [this](int i) { return model_.objectColorEdited(i); }));
}

void SceneTreePanel::setSelectedVisible(bool visible) {
  const QList<int> parts = selectedParts();
  if (parts.isEmpty()) return;
  recordEdit((visible ? tr("Show %1") : tr("Hide %1")).arg(partsText(parts)), parts, [&] {
    QMap<int, bool> change;
    for (const int i : parts) change.insert(i, visible);
    model_.setObjectVisibilities(change);
  });
}

// As one check box for the selection: all of it shown → hidden; otherwise all of it shown.
void SceneTreePanel::toggleSelectedVisible() {
  const QList<int> parts = selectedParts();
  const auto& objects = model_.scene().objects;
  const bool allShown = std::all_of(parts.begin(), parts.end(), [&](int i) {
    return i < static_cast<int>(objects.size()) && objects[static_cast<std::size_t>(i)].visible;
  });
  setSelectedVisible(!allShown);
}

void SceneTreePanel::showOnlySelected() {
  const QList<int> parts = selectedParts();
  if (parts.isEmpty()) return;
  const QList<int> all = allParts();
  recordEdit(tr("Show Only %1").arg(partsText(parts)), all, [&] {
    QMap<int, bool> visible;
    for (const int i : all) visible.insert(i, false);
    for (const int i : parts) visible.insert(i, true);
    model_.setObjectVisibilities(visible);
  });
}

QList<int> SceneTreePanel::allParts() const {
  QList<int> parts;
  parts.reserve(static_cast<qsizetype>(model_.scene().objects.size()));
  for (int i = 0; i < static_cast<int>(model_.scene().objects.size()); ++i) parts.push_back(i);
  return parts;
}

void SceneTreePanel::recordEdit(const QString& text, const QList<int>& parts, const std::function<void()>& edit) {
  std::vector<ViewerModel::PartLook> before = model_.partLooks(parts);
  edit();
  std::vector<ViewerModel::PartLook> after = model_.partLooks(parts);
  if (before != after) undo_->push(new PartsEdit(model_, text, std::move(before), std::move(after)));
}

QString SceneTreePanel::partsText(const QList<int>& parts) const {
  if (parts.size() != 1) return tr("%1 parts").arg(parts.size());
  const std::string& name = model_.scene().objects[static_cast<std::size_t>(parts.front())].name;
  return name.empty() ? tr("object %1").arg(parts.front()) : QString::fromStdString(name);
}

void SceneTreePanel::chooseSelectedColour() {
  const QList<int> parts = selectedParts();
  if (parts.isEmpty()) return;
  const QColor initial = colourOf(model_.scene().objects[static_cast<std::size_t>(parts.front())]);
  const quint64 rows = rowsBuilt_;
  const QColor chosen = QColorDialog::getColor(initial, this, tr("Colour of %1").arg(partsText(parts)));
  if (chosen.isValid() && rows == rowsBuilt_)
    recordEdit(tr("Colour of %1").arg(partsText(parts)), parts, [&] { model_.setObjectColors(parts, chosen); });
}

void SceneTreePanel::chooseSelectedOpacity() {
  const QList<int> parts = selectedParts();
  if (parts.isEmpty()) return;
  bool ok = false;
  const quint64 rows = rowsBuilt_;
  const double opacity = QInputDialog::getDouble(this, tr("Opacity"),
                                                 tr("Opacity of %1 (0 = invisible, 1 = opaque)").arg(partsText(parts)),
                                                 model_.objectOpacity(parts.front()), 0.0, 1.0, 3, &ok);
  if (!ok || rows != rowsBuilt_) return;  // another scene meanwhile
  recordEdit(tr("Opacity of %1").arg(partsText(parts)), parts, [&] {
    QMap<int, double> opacities;
    for (const int i : parts) opacities.insert(i, opacity);
    model_.setObjectOpacities(opacities);
  });
}

// The view turned to nothing, only moved and zoomed so that the selected parts fill it (hidden
// ones too: a part found by name is framed before it is shown); near and far still hold the scene.
void SceneTreePanel::fitViewToSelected() {
  mfr::Scene chosen;
  for (const int i : selectedParts()) {
    chosen.objects.push_back(model_.scene().objects[static_cast<std::size_t>(i)]);
    chosen.objects.back().visible = true;
  }
  if (!chosen.bounds().valid()) return;
  model_.setCamera(chosen.fit(model_.camera()));
}

void SceneTreePanel::selectPart(int index) {
  if (index < 0 || index >= static_cast<int>(model_.scene().objects.size()) || index >= tree_->topLevelItemCount()) {
    tree_->clearSelection();
    return;
  }
  QTreeWidgetItem* item = tree_->topLevelItem(index);
  if (item->isHidden()) filter_->clear();
  tree_->setCurrentItem(item, kName, QItemSelectionModel::ClearAndSelect | QItemSelectionModel::Rows);
  tree_->scrollToItem(item);
}
