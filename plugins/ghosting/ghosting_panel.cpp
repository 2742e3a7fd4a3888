#include "ghosting_panel.hpp"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QJsonArray>
#include <QLabel>
#include <QListWidget>
#include <QPushButton>
#include <QSet>
#include <QSignalBlocker>
#include <QSlider>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

#include "viewer_plugin.hpp"

namespace {

const QString kZThickness = QStringLiteral("zthickness");

// Each name with the count of equal names before it ("Part#0", "Part#1"): parts of one scene
// matched across a change of its part list, repeated names included.
QStringList occurrenceKeys(const QStringList& names) {
  QMap<QString, int> seen;
  QStringList keys;
  for (const QString& name : names) keys.append(name + QLatin1Char('#') + QString::number(seen[name]++));
  return keys;
}

// Slider position ↔ % of the diagonal, logarithmic between the panel's limits.
double percentAt(int position) {
  const double f = static_cast<double>(position) / GhostingPanel::kSliderSteps;
  return GhostingPanel::kMinPercent * std::pow(GhostingPanel::kMaxPercent / GhostingPanel::kMinPercent, f);
}

int positionOf(double percent) {
  const double f = std::log(percent / GhostingPanel::kMinPercent) /
                   std::log(GhostingPanel::kMaxPercent / GhostingPanel::kMinPercent);
  return static_cast<int>(std::lround(std::clamp(f, 0.0, 1.0) * GhostingPanel::kSliderSteps));
}

}  // namespace

GhostingPanel::GhostingPanel(ViewerContext& context, QWidget* parent) : QWidget(parent), context_(context) {
  setObjectName(QStringLiteral("ghostingPanel"));
  auto* layout = new QVBoxLayout(this);

  // ---- z-thickness blending
  blend_ = new QCheckBox(tr("Blend intersecting surfaces (z-thickness)"));
  blend_->setObjectName(QStringLiteral("ghostBlend"));
  blend_->setToolTip(
      tr("Operation zthickness: every fragment is a slab of the thickness below behind its surface. Surfaces "
         "closer than that (intersecting, or the same part loaded twice) blend without z-fighting; surfaces "
         "further apart composite \"over\". Needs sorted lists: an A-buffer, a k-buffer or the oracle."));
  layout->addWidget(blend_);
  blendNote_ = new QLabel;
  blendNote_->setObjectName(QStringLiteral("ghostBlendNote"));
  blendNote_->setWordWrap(true);
  blendNote_->setStyleSheet(QStringLiteral("color: #b00020;"));
  blendNote_->hide();
  layout->addWidget(blendNote_);

  auto* form = new QFormLayout;
  thicknessSlider_ = new QSlider(Qt::Horizontal);
  thicknessSlider_->setObjectName(QStringLiteral("ghostThicknessSlider"));
  thicknessSlider_->setRange(0, kSliderSteps);
  thicknessSlider_->setToolTip(
      tr("Slab thickness, %1 % … %2 % of the scene's diagonal (logarithmic)").arg(kMinPercent).arg(kMaxPercent));
  thicknessPercent_ = new QLabel;
  thicknessPercent_->setObjectName(QStringLiteral("ghostThicknessPercent"));
  thicknessPercent_->setMinimumWidth(fontMetrics().horizontalAdvance(QStringLiteral("10.00 %")));
  auto* sliderRow = new QHBoxLayout;
  sliderRow->addWidget(thicknessSlider_, 1);
  sliderRow->addWidget(thicknessPercent_);
  form->addRow(tr("Thickness"), sliderRow);
  thickness_ = new QDoubleSpinBox;
  thickness_->setObjectName(QStringLiteral("ghostThickness"));
  thickness_->setDecimals(6);
  thickness_->setRange(1.0e-6, 1.0e9);
  thickness_->setKeyboardTracking(false);
  thickness_->setToolTip(tr("Slab thickness in scene units"));
  auto* reset = new QPushButton(tr("Default"));
  reset->setObjectName(QStringLiteral("ghostThicknessDefault"));
  reset->setToolTip(tr("1 % of the scene's diagonal"));
  auto* unitsRow = new QHBoxLayout;
  unitsRow->addWidget(thickness_, 1);
  unitsRow->addWidget(reset);
  form->addRow(tr("Scene units"), unitsRow);
  layout->addLayout(form);

  // ---- ghosting
  layout->addWidget(new QLabel(tr("Parts in focus (keep their opacity):")));
  parts_ = new QListWidget;
  parts_->setObjectName(QStringLiteral("ghostParts"));
  parts_->setMaximumHeight(160);
  layout->addWidget(parts_);
  ghost_ = new QCheckBox(tr("Ghost the other parts"));
  ghost_->setObjectName(QStringLiteral("ghostOthers"));
  ghost_->setToolTip(tr("Every part not in focus gets the opacity of the slider; off, each gets its own back"));
  layout->addWidget(ghost_);
  auto* ghostRow = new QHBoxLayout;
  ghostSlider_ = new QSlider(Qt::Horizontal);
  ghostSlider_->setObjectName(QStringLiteral("ghostOpacity"));
  ghostSlider_->setRange(2, 100);  // opacity in hundredths
  ghostSlider_->setValue(static_cast<int>(std::lround(kDefaultGhostOpacity * 100.0)));
  ghostSlider_->setToolTip(tr("Opacity of the ghosted parts (0.02 … 1)"));
  ghostValue_ = new QLabel;
  ghostValue_->setMinimumWidth(fontMetrics().horizontalAdvance(QStringLiteral("0.00")));
  ghostRow->addWidget(new QLabel(tr("Opacity")));
  ghostRow->addWidget(ghostSlider_, 1);
  ghostRow->addWidget(ghostValue_);
  layout->addLayout(ghostRow);
  auto* restore = new QPushButton(tr("Restore Opacities"));
  restore->setObjectName(QStringLiteral("ghostRestore"));
  restore->setToolTip(tr("Every part back to its opacity as loaded; ghosting off"));
  layout->addWidget(restore, 0, Qt::AlignLeft);
  layout->addStretch();

  connect(blend_, &QCheckBox::toggled, this, &GhostingPanel::setBlend);
  connect(&context_, &ViewerContext::operationChanged, this, &GhostingPanel::showBlendState);
  connect(&context_, &ViewerContext::methodChanged, this, &GhostingPanel::showBlendState);
  connect(thicknessSlider_, &QSlider::valueChanged, this, &GhostingPanel::thicknessFromSlider);
  connect(thickness_, &QDoubleSpinBox::valueChanged, this, [this](double v) { context_.setZThickness(v); });
  connect(reset, &QPushButton::clicked, this, [this] { context_.setZThickness(0.0); });
  connect(&context_, &ViewerContext::zThicknessChanged, this, &GhostingPanel::showThickness);
  connect(&context_, &ViewerContext::sceneChanged, this, &GhostingPanel::sceneChanged);
  connect(parts_, &QListWidget::itemChanged, this, &GhostingPanel::applyGhosting);
  connect(ghost_, &QCheckBox::toggled, this, &GhostingPanel::applyGhosting);
  connect(ghostSlider_, &QSlider::valueChanged, this, [this] {
    ghostValue_->setText(QString::number(ghostOpacity(), 'f', 2));
    if (ghost_->isChecked()) applyGhosting();
  });
  connect(restore, &QPushButton::clicked, this, &GhostingPanel::restoreOpacities);
  ghostValue_->setText(QString::number(ghostOpacity(), 'f', 2));
  sceneChanged();
  showBlendState();
}

double GhostingPanel::diagonal() const {
  return context_.zThicknessDefault() / 0.01;  // the default is 1 % of the diagonal
}

double GhostingPanel::ghostOpacity() const {
  return ghostSlider_->value() / 100.0;
}

bool GhostingPanel::isFocus(int objectId) const {
  const QListWidgetItem* item = parts_->item(objectId);
  return item && item->checkState() == Qt::Checked;
}

// The names without the viewer's isosurfaces ("VOLUME = VALUE", ViewerContext 1.8): the scene's
// own parts.
QStringList GhostingPanel::ownParts(const QStringList& names) const {
  const QStringList volumes = context_.volumeNames();
  QStringList own;
  for (const QString& name : names)
    if (std::none_of(volumes.begin(), volumes.end(),
                     [&name](const QString& v) { return name.startsWith(v + QStringLiteral(" = ")); }))
      own.append(name);
  return own;
}

void GhostingPanel::sceneChanged() {
  const QStringList names = context_.hasScene() ? context_.objectNames() : QStringList{};
  const quint64 serial = context_.sceneSerial();
  if (names != names_ || serial != sceneSerial_) {
    // Isosurfaces added or removed (the scene's own parts unchanged): the parts that stay keep
    // their focus, and ghosting goes on over the new ones. Another scene: nothing of it is ghosted,
    // even where its parts have the old one's names.
    const bool sameScene = serial == sceneSerial_ && !names_.isEmpty() && ownParts(names) == ownParts(names_);
    sceneSerial_ = serial;
    QMap<QString, Qt::CheckState> focus;
    QMap<QString, double> before;  // opacities before ghosting, of the parts still ghosted
    if (sameScene) {
      const QStringList keys = occurrenceKeys(names_);
      for (int id = 0; id < parts_->count(); ++id) {
        focus.insert(keys[id], parts_->item(id)->checkState());
        // A part at the ghost opacity is still ghosted; one made again has an opacity of its own.
        if (saved_.contains(id) && std::abs(context_.objectOpacity(id) - ghostOpacity()) < 1e-6)
          before.insert(keys[id], saved_.value(id));
      }
    }
    names_ = names;
    saved_.clear();
    {
      const QSignalBlocker blockList(parts_), blockGhost(ghost_);
      if (!sameScene) ghost_->setChecked(false);
      parts_->clear();
      const QStringList keys = occurrenceKeys(names);
      for (int id = 0; id < names.size(); ++id) {
        auto* item = new QListWidgetItem(names[id], parts_);
        item->setFlags(item->flags() | Qt::ItemIsUserCheckable);
        item->setCheckState(focus.value(keys[id], Qt::Unchecked));
        if (before.contains(keys[id])) saved_.insert(id, before.value(keys[id]));
      }
    }
    if (sameScene && ghost_->isChecked()) applyGhosting();
  }
  showThickness();  // the default follows the scene's size
}

// ---- z-thickness ----------------------------------------------------------------------------

void GhostingPanel::setBlend(bool on) {
  const QString operation = context_.operation();
  if (!on) {
    if (operation == kZThickness) {
      if (!previousMethod_.isEmpty() && context_.method() == QLatin1String(kBlendMethod))
        context_.setMethod(previousMethod_);
      context_.setOperation(previousOperation_.isEmpty() ? QStringLiteral("auto") : previousOperation_);
    }
    previousMethod_.clear();
    showBlendState();
    return;
  }
  const QString method = context_.method();
  // A switch turned on anew: what an earlier one switched from is stale (the operation changed
  // in the Method panel since), and a method that can blend is kept, so off must not bring back
  // the older one (it did: a bug hunt).
  if (operation != kZThickness) {
    previousOperation_ = operation;
    previousMethod_.clear();
  }
  if (!context_.supportsOperation(method, kZThickness)) {
    previousMethod_ = method;
    context_.setMethod(QLatin1String(kBlendMethod));
  }
  context_.setOperation(kZThickness);
  showBlendState();
}

void GhostingPanel::showBlendState() {
  const bool on = context_.operation() == kZThickness;
  {
    const QSignalBlocker block(blend_);
    blend_->setChecked(on);
  }
  const QString method = context_.method();
  const bool refused = on && !context_.supportsOperation(method, kZThickness);
  blendNote_->setText(refused ? tr("%1 keeps no sorted lists and cannot blend: choose an A-buffer, a k-buffer "
                                   "or the oracle.")
                                    .arg(method)
                              : QString());
  blendNote_->setVisible(refused);
}

void GhostingPanel::showThickness() {
  const double diag = diagonal();
  const double value = context_.zThickness() > 0.0 ? context_.zThickness() : context_.zThicknessDefault();
  const double percent = diag > 0.0 ? 100.0 * value / diag : 1.0;
  const QSignalBlocker blockSlider(thicknessSlider_), blockBox(thickness_);
  thicknessSlider_->setValue(positionOf(percent));
  thickness_->setSingleStep(std::max(1.0e-6, diag * 0.001));
  thickness_->setValue(value);
  thicknessPercent_->setText(QStringLiteral("%1 %").arg(percent, 0, 'f', percent < 0.1 ? 3 : 2));
}

void GhostingPanel::thicknessFromSlider(int position) {
  context_.setZThickness(percentAt(position) / 100.0 * diagonal());
}

// ---- ghosting -------------------------------------------------------------------------------

void GhostingPanel::applyGhosting() {
  const bool ghosting = ghost_->isChecked();
  QMap<int, double> changes;
  for (int id = 0; id < parts_->count(); ++id) {
    if (ghosting && !isFocus(id)) {
      if (!saved_.contains(id)) saved_.insert(id, context_.objectOpacity(id));
      changes.insert(id, ghostOpacity());
    } else if (saved_.contains(id)) {
      changes.insert(id, saved_.take(id));  // in focus again, or ghosting off: its own opacity back
    }
  }
  context_.setObjectOpacities(changes);
}

void GhostingPanel::restoreOpacities() {
  {
    const QSignalBlocker block(ghost_);
    ghost_->setChecked(false);
  }
  saved_.clear();
  QMap<int, double> original;
  for (int id = 0; id < parts_->count(); ++id) original.insert(id, context_.loadedObjectOpacity(id));
  context_.setObjectOpacities(original);
}

// ---- settings -------------------------------------------------------------------------------

// Each part's name in settings: the first part of a name by the name, the n-th (n ≥ 1) as
// "name#n", so that parts of one name keep their own focus and opacity (by the name alone, the
// second took the first's: a bug hunt) — or the next free number where a part is itself named
// "name#n" (it shared the key with the second "name": a review).
QStringList GhostingPanel::settingNames() const {
  QStringList names;
  for (int id = 0; id < parts_->count(); ++id) names << parts_->item(id)->text();
  QSet<QString> taken(names.begin(), names.end());
  QMap<QString, int> last;  // the last number given to each name
  QSet<QString> first;
  QStringList labels;
  for (const QString& name : names) {
    if (!first.contains(name)) {
      first.insert(name);
      labels << name;
      continue;
    }
    int n = last.value(name) + 1;
    while (taken.contains(name + QLatin1Char('#') + QString::number(n))) ++n;
    last[name] = n;
    labels << name + QLatin1Char('#') + QString::number(n);
    taken.insert(labels.back());
  }
  return labels;
}

QJsonObject GhostingPanel::saveSettings() const {
  QJsonArray focus;
  QJsonObject ghosted;
  const QStringList labels = settingNames();
  for (int id = 0; id < parts_->count(); ++id) {
    if (isFocus(id)) focus.append(labels[id]);
    if (saved_.contains(id)) ghosted.insert(labels[id], saved_.value(id));
  }
  return {{QStringLiteral("focus"), focus},
          {QStringLiteral("ghost"), ghost_->isChecked()},
          {QStringLiteral("ghost_opacity"), ghostOpacity()},
          {QStringLiteral("ghosted"), ghosted},
          {QStringLiteral("previous_operation"), previousOperation_},
          {QStringLiteral("previous_method"), previousMethod_}};
}

void GhostingPanel::loadSettings(const QJsonObject& settings) {
  if (!context_.hasScene()) return;
  sceneChanged();  // the list of this scene's parts (sessions load settings before sceneChanged)
  previousOperation_ = settings.value(QStringLiteral("previous_operation")).toString();
  previousMethod_ = settings.value(QStringLiteral("previous_method")).toString();
  const QStringList focus = settings.value(QStringLiteral("focus")).toVariant().toStringList();
  const QJsonObject ghosted = settings.value(QStringLiteral("ghosted")).toObject();
  {
    const QSignalBlocker blockList(parts_), blockGhost(ghost_), blockSlider(ghostSlider_);
    const double opacity = settings.value(QStringLiteral("ghost_opacity")).toDouble(kDefaultGhostOpacity);
    if (!(opacity >= 0.02 && opacity <= 1.0))
      context_.note(tr("ghosting: ghost_opacity %1 is outside 0.02 … 1: %2 is used")
                        .arg(opacity)
                        .arg(std::clamp(opacity, 0.02, 1.0)));
    ghostSlider_->setValue(static_cast<int>(std::lround(std::clamp(opacity, 0.02, 1.0) * 100.0)));
    ghostValue_->setText(QString::number(ghostOpacity(), 'f', 2));
    // The slider holds hundredths: 0.025 drew as 0.03 without a word (a bug hunt).
    if (opacity >= 0.02 && opacity <= 1.0 && std::abs(ghostOpacity() - opacity) > 1e-9)
      context_.note(tr("ghosting: ghost_opacity %1 is not a whole hundredth: %2 is used")
                        .arg(opacity)
                        .arg(ghostOpacity(), 0, 'f', 2));
    saved_.clear();
    const QStringList labels = settingNames();
    // Sets, not lists: a session ghosting n parts looked each up in a list of n (quadratic; a hunt).
    const QSet<QString> focusSet(focus.begin(), focus.end());
    const QSet<QString> labelSet(labels.begin(), labels.end());
    for (int id = 0; id < parts_->count(); ++id) {
      QListWidgetItem* item = parts_->item(id);
      item->setCheckState(focusSet.contains(labels[id]) ? Qt::Checked : Qt::Unchecked);
      // The opacities the session's ghosted parts had before (the session's objects hold the ghosted ones).
      if (ghosted.contains(labels[id])) {
        const QJsonValue before = ghosted.value(labels[id]);
        // Another type (a string, null) read as 0, and 5 was clamped, without a word (a bug hunt).
        if (!before.isDouble() || !(before.toDouble() >= 0.0 && before.toDouble() <= 1.0))
          context_.note(tr("ghosting: ghosted '%1': expected an opacity in 0 … 1 (left out)").arg(labels[id]));
        else
          saved_.insert(id, before.toDouble());
      }
    }
    ghost_->setChecked(settings.value(QStringLiteral("ghost")).toBool(false));
    // A focus part the scene lacks was dropped without a word (the rest was ghosted around nothing).
    QStringList missing, unknown;
    for (const QString& name : focus)
      if (!labelSet.contains(name)) missing << QStringLiteral("'%1'").arg(name);
    if (!missing.isEmpty())
      context_.note(tr("ghosting: no part %1 in this scene to focus on").arg(missing.join(QStringLiteral(", "))));
    for (auto it = ghosted.begin(); it != ghosted.end(); ++it)
      if (!labelSet.contains(it.key())) unknown << QStringLiteral("'%1'").arg(it.key());
    if (!unknown.isEmpty())
      context_.note(
          tr("ghosting: ghosted: no part %1 in this scene (left out)").arg(unknown.join(QStringLiteral(", "))));
  }
  applyGhosting();
  showBlendState();
}
