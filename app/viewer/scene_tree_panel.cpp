#include "scene_tree_panel.hpp"

#include <QColorDialog>
#include <QHeaderView>
#include <QMenu>
#include <QPixmap>
#include <QTreeWidget>
#include <QVBoxLayout>

#include <QSignalBlocker>

#include <algorithm>
#include <cmath>

#include "viewer_model.hpp"

namespace {

enum Column { kName = 0, kColour = 1, kOpacity = 2, kTriangles = 3 };

QColor colourOf(const mfr::Object& o) {
  return QColor::fromRgbF(o.material.color.r, o.material.color.g, o.material.color.b);
}

// The colour column's text: the colour's name, or "file colours" while the mesh's per-vertex colours
// show (multiplied by the swatch's colour, white for molecules).
QString colourText(const mfr::Object& o) {
  const bool perVertex = o.material.vertexColors && o.mesh && !o.mesh->colors.empty();
  return perVertex ? QObject::tr("file colours") : colourOf(o).name();
}

QIcon swatch(const QColor& colour) {
  QPixmap pixmap(16, 16);
  pixmap.fill(colour);
  return QIcon(pixmap);
}

}  // namespace

SceneTreePanel::SceneTreePanel(ViewerModel& model, QWidget* parent) : QWidget(parent), model_(model) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
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
  layout->addWidget(tree_);
  connect(tree_, &QTreeWidget::itemChanged, this, &SceneTreePanel::itemChanged);
  connect(tree_, &QTreeWidget::itemClicked, this, &SceneTreePanel::itemClicked);
  // Right-click: back to the file's colour (a molecule's element colours) after choosing one.
  tree_->setContextMenuPolicy(Qt::CustomContextMenu);
  connect(tree_, &QWidget::customContextMenuRequested, this, [this](const QPoint& at) {
    QTreeWidgetItem* item = tree_->itemAt(at);
    if (!item || item->data(kName, Qt::UserRole).toInt() < 0) return;  // a volume row
    const int index = item->data(kName, Qt::UserRole).toInt();
    QMenu menu(this);
    QAction* reset =
        menu.addAction(tr("Reset Colour to the File's"), this, [this, index] { model_.resetObjectColor(index); });
    reset->setObjectName(QStringLiteral("resetColourAction"));
    reset->setEnabled(model_.objectColorEdited(index));
    menu.exec(tree_->viewport()->mapToGlobal(at));
  });
  connect(&model_, &ViewerModel::sceneLoaded, this, &SceneTreePanel::rebuild);
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

void SceneTreePanel::showValues() {
  const auto& objects = model_.scene().objects;
  const auto& volumes = model_.scene().volumes;
  if (tree_->topLevelItemCount() != static_cast<int>(objects.size() + volumes.size())) return;
  const QSignalBlocker block(tree_);
  for (std::size_t v = 0; v < volumes.size(); ++v) {
    QTreeWidgetItem* item = tree_->topLevelItem(static_cast<int>(objects.size() + v));
    item->setCheckState(kName, volumes[v].visible ? Qt::Checked : Qt::Unchecked);
    // Another field read (the Volume panel's Field): its name and grid.
    item->setText(kName, volumeText(volumes[v], v));
    item->setText(kColour, gridText(volumes[v]));
  }
  for (int i = 0; i < static_cast<int>(objects.size()); ++i) {
    QTreeWidgetItem* item = tree_->topLevelItem(i);
    const mfr::Object& o = objects[static_cast<std::size_t>(i)];
    item->setCheckState(kName, o.visible ? Qt::Checked : Qt::Unchecked);
    if (item->text(kColour) != colourText(o) || item->data(kColour, Qt::UserRole).value<QColor>() != colourOf(o)) {
      item->setIcon(kColour, swatch(colourOf(o)));
      item->setText(kColour, colourText(o));
      item->setData(kColour, Qt::UserRole, colourOf(o));
    }
    item->setData(kOpacity, Qt::EditRole, std::round(o.material.color.a * 1000.0) / 1000.0);
  }
}

void SceneTreePanel::rebuild() {
  rebuilding_ = true;
  tree_->clear();
  const auto& objects = model_.scene().objects;
  QList<QTreeWidgetItem*> items;
  items.reserve(static_cast<qsizetype>(objects.size()));
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const mfr::Object& o = objects[i];
    auto* item = new QTreeWidgetItem;
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
  rebuilding_ = false;
}

void SceneTreePanel::itemChanged(QTreeWidgetItem* item, int column) {
  if (rebuilding_) return;
  if (const int volume = volumeOfRow(item); volume >= 0) {
    if (column == kName) model_.setVolumeVisibleAt(volume, item->checkState(kName) == Qt::Checked);
    return;
  }
  const int index = item->data(kName, Qt::UserRole).toInt();
  if (column == kName) {
    model_.setObjectVisible(index, item->checkState(kName) == Qt::Checked);
  } else if (column == kOpacity) {
    const double opacity = std::clamp(item->data(kOpacity, Qt::EditRole).toDouble(), 0.0, 1.0);
    model_.setObjectOpacity(index, opacity);
    showValues();  // the clamped value, also when it was the part's opacity already (no sceneChanged)
  }
}

void SceneTreePanel::itemClicked(QTreeWidgetItem* item, int column) {
  if (column != kColour || volumeOfRow(item) >= 0) return;
  const int index = item->data(kName, Qt::UserRole).toInt();
  const QColor initial = colourOf(model_.scene().objects[static_cast<std::size_t>(index)]);
  const QColor chosen = QColorDialog::getColor(initial, this, tr("Colour of %1").arg(item->text(kName)));
  if (!chosen.isValid()) return;
  model_.setObjectColor(index, chosen);
}
