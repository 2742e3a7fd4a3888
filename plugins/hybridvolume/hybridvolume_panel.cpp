#include "hybridvolume_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QJsonArray>
#include <QLabel>
#include <QLineEdit>
#include <QPainter>
#include <QPixmap>
#include <QPushButton>
#include <QRegularExpression>
#include <QSignalBlocker>
#include <QSlider>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

#include "transfer_function_editor.hpp"
#include "viewer_plugin.hpp"

namespace {

const QString kVolume = QStringLiteral("volume");
const QString kCustom = QStringLiteral("Custom");

// Slider position ↔ value, logarithmic between lo and hi.
double logAt(int position, double lo, double hi) {
  return lo * std::pow(hi / lo, static_cast<double>(position) / HybridVolumePanel::kSliderSteps);
}

int logPosition(double value, double lo, double hi) {
  if (!(value > 0.0)) return 0;
  const double f = std::log(value / lo) / std::log(hi / lo);
  return static_cast<int>(std::lround(std::clamp(f, 0.0, 1.0) * HybridVolumePanel::kSliderSteps));
}

bool sameTransfer(const mfr::TransferFunction& a, const mfr::TransferFunction& b) {
  if (a.unitDistance != b.unitDistance || a.points.size() != b.points.size()) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    if (a.points[i].value != b.points[i].value || a.points[i].color != b.points[i].color) return false;
  return true;
}

QJsonObject transferToJson(const mfr::TransferFunction& t) {
  QJsonArray points;
  for (const mfr::TransferPoint& p : t.points)
    points.append(QJsonArray{p.value, p.color.r, p.color.g, p.color.b, p.color.a});
  return {{QStringLiteral("unit_distance"), t.unitDistance}, {QStringLiteral("points"), points}};
}

// A transfer function from settings; `unitDistance` where the key is left out. What is not one
// (a point of 3 numbers was dropped, a unit distance "x" read as 1: a bug hunt) is named in `error`.
mfr::TransferFunction transferFromJson(const QJsonObject& json, double unitDistance, QString& error) {
  mfr::TransferFunction t;
  t.unitDistance = unitDistance;
  if (json.contains(QStringLiteral("unit_distance"))) {
    if (!json.value(QStringLiteral("unit_distance")).isDouble())
      error = QStringLiteral("unit_distance: expected a number");
    t.unitDistance = json.value(QStringLiteral("unit_distance")).toDouble();
  }
  const QJsonArray points = json.value(QStringLiteral("points")).toArray();
  for (qsizetype i = 0; i < points.size(); ++i) {
    const QJsonArray p = points[i].toArray();
    if (p.size() != 5 || !std::all_of(p.begin(), p.end(), [](const QJsonValue& x) { return x.isDouble(); })) {
      if (error.isEmpty()) error = QStringLiteral("points[%1]: expected [value, r, g, b, a]").arg(i);
      continue;
    }
    t.points.push_back(
        {p[0].toDouble(), glm::vec4(glm::dvec4(p[1].toDouble(), p[2].toDouble(), p[3].toDouble(), p[4].toDouble()))});
  }
  return t;
}

QDoubleSpinBox* unitSpinBox(const char* name, const QString& tip) {
  auto* box = new QDoubleSpinBox;
  box->setObjectName(QLatin1String(name));
  box->setRange(0.0, 1.0);
  box->setDecimals(3);
  box->setSingleStep(0.01);
  box->setKeyboardTracking(false);
  box->setToolTip(tip);
  return box;
}

QComboBox* chooser(const char* name, const QString& tip) {
  auto* box = new QComboBox;
  box->setObjectName(QLatin1String(name));
  box->setToolTip(tip);
  return box;
}

// The combo box's items, replaced only when they differ (the current index is set by the caller).
void setItems(QComboBox* box, const QStringList& items) {
  QStringList shown;
  for (int i = 0; i < box->count(); ++i) shown << box->itemText(i);
  if (shown == items) return;
  box->clear();
  box->addItems(items);
}

// "label [widget]" on one line, hidden until there is something to choose.
QWidget* hiddenRow(const QString& label, QWidget* widget) {
  auto* row = new QWidget;
  auto* layout = new QHBoxLayout(row);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(new QLabel(label));
  layout->addWidget(widget, 1);
  row->hide();
  return row;
}

QString bytesText(double bytes) {
  if (bytes >= 1024.0 * 1024.0) return QStringLiteral("%1 MiB").arg(bytes / (1024.0 * 1024.0), 0, 'f', 1);
  if (bytes >= 1024.0) return QStringLiteral("%1 KiB").arg(bytes / 1024.0, 0, 'f', 1);
  return QStringLiteral("%1 B").arg(bytes);
}

}  // namespace

HybridVolumePanel::HybridVolumePanel(ViewerContext& context, QWidget* parent) : QWidget(parent), context_(context) {
  setObjectName(QStringLiteral("hybridVolumePanel"));
  auto* layout = new QVBoxLayout(this);

  // A scene with several volumes: which one the controls below show and edit.
  volumeChoice_ = chooser("hvVolume", tr("The volume these controls show and edit. Up to four volumes are drawn at "
                                         "once; where they overlap their media mix (extinctions add, colours "
                                         "weighted by extinction)."));
  volumeRow_ = hiddenRow(tr("Volume"), volumeChoice_);
  layout->addWidget(volumeRow_);
  // A file with several arrays (.vti, .vtk) or grids (.vdb): which one is read.
  fieldChoice_ = chooser("hvField", tr("The array (VTK files) or grid (OpenVDB files) of the volume's file that is "
                                       "drawn. Another one is read from the file in its place; its transfer function "
                                       "starts at the default over its values."));
  fieldRow_ = hiddenRow(tr("Field"), fieldChoice_);
  layout->addWidget(fieldRow_);
  fieldNote_ = new QLabel;
  fieldNote_->setObjectName(QStringLiteral("hvFieldNote"));
  fieldNote_->setWordWrap(true);
  fieldNote_->hide();
  layout->addWidget(fieldNote_);

  show_ = new QCheckBox(tr("Show volume"));
  show_->setObjectName(QStringLiteral("hvShow"));
  show_->setToolTip(
      tr("Operation volume: the scene's volume ray-marched between each pixel's sorted surface "
         "fragments, every surface at its own depth. Needs sorted lists: an A-buffer, a k-buffer "
         "or the oracle (abuffer-sbuffer is chosen for a method without them)."));
  layout->addWidget(show_);
  note_ = new QLabel;
  note_->setObjectName(QStringLiteral("hvNote"));
  note_->setWordWrap(true);
  note_->setStyleSheet(QStringLiteral("color: #b00020;"));
  note_->hide();
  layout->addWidget(note_);

  controls_ = new QWidget;
  auto* form = new QFormLayout(controls_);
  form->setContentsMargins(0, 0, 0, 0);
  preset_ = new QComboBox;
  preset_->setObjectName(QStringLiteral("hvPreset"));
  for (const QString& name : context_.transferPresetNames()) preset_->addItem(name, name);
  preset_->addItem(tr("Custom"), kCustom);
  preset_->setToolTip(
      tr("Transfer function: a preset over the window, or Custom (the scene's own function, or "
         "one set elsewhere, stretched onto the window)"));
  form->addRow(tr("Transfer"), preset_);

  windowMin_ = new QDoubleSpinBox;
  windowMin_->setObjectName(QStringLiteral("hvWindowMin"));
  windowMax_ = new QDoubleSpinBox;
  windowMax_->setObjectName(QStringLiteral("hvWindowMax"));
  for (QDoubleSpinBox* box : {windowMin_, windowMax_}) {
    box->setDecimals(4);
    box->setRange(-1.0e12, 1.0e12);
    box->setKeyboardTracking(false);
  }
  windowMin_->setToolTip(tr("Scalar value the transfer function starts at (below: its first colour)"));
  windowMax_->setToolTip(tr("Scalar value the transfer function ends at (above: its last colour)"));
  auto* windowRow = new QHBoxLayout;
  windowRow->addWidget(windowMin_, 1);
  windowRow->addWidget(new QLabel(QStringLiteral("…")));
  windowRow->addWidget(windowMax_, 1);
  form->addRow(tr("Window"), windowRow);

  opacity_ = new QSlider(Qt::Horizontal);
  opacity_->setObjectName(QStringLiteral("hvOpacity"));
  opacity_->setRange(0, kSliderSteps);
  opacity_->setValue(logPosition(1.0, kMinScale, kMaxScale));
  opacity_->setToolTip(
      tr("Opacity scale %1× … %2× (logarithmic): multiplies the extinction, as a shorter unit distance would")
          .arg(kMinScale)
          .arg(kMaxScale));
  opacityValue_ = new QLabel;
  opacityValue_->setObjectName(QStringLiteral("hvOpacityValue"));
  opacityValue_->setMinimumWidth(fontMetrics().horizontalAdvance(QStringLiteral("20.00×")));
  auto* opacityRow = new QHBoxLayout;
  opacityRow->addWidget(opacity_, 1);
  opacityRow->addWidget(opacityValue_);
  form->addRow(tr("Opacity"), opacityRow);
  shade_ = new QCheckBox(tr("Gradient lighting"));
  shade_->setObjectName(QStringLiteral("hvShade"));
  shade_->setToolTip(
      tr("Shade the medium by its gradient with a headlight (Levoy 1988): boundaries inside the "
         "volume read as surfaces; homogeneous regions stay unshaded"));
  form->addRow(tr("Shading"), shade_);

  editor_ = new TransferFunctionEditor;
  editor_->setObjectName(QStringLiteral("hvTransferEditor"));
  form->addRow(editor_);
  pointFields_ = new QWidget;
  auto* pointForm = new QFormLayout(pointFields_);
  pointForm->setContentsMargins(0, 0, 0, 0);
  pointValue_ = new QDoubleSpinBox;
  pointValue_->setObjectName(QStringLiteral("hvPointValue"));
  pointValue_->setDecimals(6);
  pointValue_->setRange(-1.0e12, 1.0e12);
  pointValue_->setKeyboardTracking(false);
  pointValue_->setToolTip(tr("The selected point's scalar value (the end points stay at the window's ends)"));
  pointOpacity_ = unitSpinBox("hvPointOpacity", tr("The selected point's opacity: what one unit distance absorbs"));
  pointOpacity_->setDecimals(4);
  auto* pointRow = new QHBoxLayout;
  pointRow->addWidget(pointValue_, 3);
  pointRow->addWidget(new QLabel(tr("opacity")));
  pointRow->addWidget(pointOpacity_, 2);
  pointForm->addRow(tr("Point"), pointRow);
  pointRed_ = unitSpinBox("hvPointRed", tr("The selected point's red, 0 … 1"));
  pointGreen_ = unitSpinBox("hvPointGreen", tr("The selected point's green, 0 … 1"));
  pointBlue_ = unitSpinBox("hvPointBlue", tr("The selected point's blue, 0 … 1"));
  pointColor_ = new QPushButton;
  pointColor_->setObjectName(QStringLiteral("hvPointColor"));
  pointColor_->setToolTip(tr("Choose the selected point's colour"));
  pointColor_->setFixedWidth(pointColor_->sizeHint().height() * 3 / 2);
  auto* colorRow = new QHBoxLayout;
  for (QDoubleSpinBox* box : {pointRed_, pointGreen_, pointBlue_}) colorRow->addWidget(box, 1);
  colorRow->addWidget(pointColor_);
  pointForm->addRow(tr("Colour"), colorRow);
  form->addRow(pointFields_);

  preview_ = new QLabel;
  preview_->setObjectName(QStringLiteral("hvPreview"));
  preview_->setMinimumHeight(28);
  preview_->setScaledContents(true);
  preview_->setToolTip(
      tr("The transfer function's table over the window: colour over a checkerboard by the "
         "opacity of one unit distance, and that opacity as a curve"));
  auto* asLoaded = new QPushButton(tr("As Loaded"));
  asLoaded->setObjectName(QStringLiteral("hvAsLoaded"));
  asLoaded->setToolTip(tr("The scene's own transfer function back"));
  form->addRow(preview_);
  form->addRow(QString(), asLoaded);
  error_ = new QLabel;
  error_->setObjectName(QStringLiteral("hvError"));
  error_->setWordWrap(true);
  error_->setStyleSheet(QStringLiteral("color: #b00020;"));
  error_->hide();
  form->addRow(error_);

  stepSlider_ = new QSlider(Qt::Horizontal);
  stepSlider_->setObjectName(QStringLiteral("hvStepSlider"));
  stepSlider_->setRange(0, kSliderSteps);
  stepSlider_->setToolTip(
      tr("Ray-march step, %1× … %2× the default (logarithmic)").arg(kMinStepFactor).arg(kMaxStepFactor));
  form->addRow(tr("Step"), stepSlider_);
  step_ = new QDoubleSpinBox;
  step_->setObjectName(QStringLiteral("hvStep"));
  step_->setDecimals(6);
  step_->setRange(1.0e-6, 1.0e9);
  step_->setKeyboardTracking(false);
  step_->setToolTip(tr("Ray-march step in scene units"));
  auto* stepDefault = new QPushButton(tr("Default"));
  stepDefault->setObjectName(QStringLiteral("hvStepDefault"));
  stepDefault->setToolTip(tr("Half the volume's smallest grid spacing"));
  auto* stepRow = new QHBoxLayout;
  stepRow->addWidget(step_, 1);
  stepRow->addWidget(stepDefault);
  form->addRow(tr("Scene units"), stepRow);

  // Isosurfaces (ParaView's Contour): parts of their own, drawn by every method like any other.
  isoValues_ = new QLineEdit;
  isoValues_->setObjectName(QStringLiteral("hvIsoValues"));
  isoValues_->setPlaceholderText(tr("values, e.g. -142, 226"));
  isoValues_->setToolTip(
      tr("Isosurfaces of the volume at these values (at most 16, inside its range), each a part "
         "named \"volume = value\" coloured by its value; the volume is hidden while they are "
         "made (Show volume draws it again). Empty: none"));
  isoOpacity_ = unitSpinBox("hvIsoOpacity", tr("Opacity of the isosurfaces"));
  isoOpacity_->setDecimals(2);
  isoOpacity_->setValue(0.5);
  auto* isoApply = new QPushButton(tr("Apply"));
  isoApply->setObjectName(QStringLiteral("hvIsoApply"));
  auto* isoRow = new QHBoxLayout;
  isoRow->addWidget(isoValues_, 3);
  isoRow->addWidget(isoOpacity_, 1);
  isoRow->addWidget(isoApply);
  form->addRow(tr("Isosurfaces"), isoRow);
  isoNote_ = new QLabel;
  isoNote_->setObjectName(QStringLiteral("hvIsoNote"));
  isoNote_->setWordWrap(true);
  form->addRow(isoNote_);
  layout->addWidget(controls_);

  info_ = new QLabel;
  info_->setObjectName(QStringLiteral("hvInfo"));
  info_->setWordWrap(true);
  info_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(info_);
  layout->addStretch();

  connect(show_, &QCheckBox::toggled, this, &HybridVolumePanel::setShow);
  connect(volumeChoice_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (index >= 0) context_.setCurrentVolume(index);
  });
  connect(fieldChoice_, &QComboBox::activated, this, [this](int index) {
    if (index >= 0) context_.setVolumeField(fieldChoice_->itemText(index));
  });
  connect(shade_, &QCheckBox::toggled, this, [this](bool on) { context_.setVolumeShading(on); });
  connect(&context_, &ViewerContext::operationChanged, this, &HybridVolumePanel::showState);
  connect(&context_, &ViewerContext::methodChanged, this, &HybridVolumePanel::showState);
  connect(&context_, &ViewerContext::volumeChanged, this, &HybridVolumePanel::volumeChanged);
  connect(&context_, &ViewerContext::frameRendered, this, &HybridVolumePanel::showInfo);
  connect(&context_, &ViewerContext::frameErrorChanged, this, &HybridVolumePanel::showInfo);
  connect(&context_, &ViewerContext::sceneChanged, this, &HybridVolumePanel::showIsosurfaces);
  connect(preset_, &QComboBox::currentIndexChanged, this, &HybridVolumePanel::applyTransfer);
  connect(windowMin_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    windowLow_ = v;
    applyTransfer();
  });
  connect(windowMax_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    windowHigh_ = v;
    applyTransfer();
  });
  connect(editor_, &TransferFunctionEditor::edited, this, &HybridVolumePanel::applyEditor);
  connect(editor_, &TransferFunctionEditor::selectionChanged, this, &HybridVolumePanel::showSelectedPoint);
  for (QDoubleSpinBox* box : {pointValue_, pointOpacity_, pointRed_, pointGreen_, pointBlue_})
    connect(box, &QDoubleSpinBox::valueChanged, this, &HybridVolumePanel::editSelectedPoint);
  connect(pointColor_, &QPushButton::clicked, this, [this] { editor_->editPointColor(editor_->selectedPoint()); });
  connect(opacity_, &QSlider::valueChanged, this, [this] {
    showScaleValue();
    applyTransfer();
  });
  connect(asLoaded, &QPushButton::clicked, this, [this] {
    const QString reason = context_.setTransferFunction(context_.loadedTransferFunction());
    error_->setText(reason);
    error_->setVisible(!reason.isEmpty());
    resetToCurrent();
  });
  connect(isoApply, &QPushButton::clicked, this, &HybridVolumePanel::applyIsosurfaces);
  connect(isoValues_, &QLineEdit::returnPressed, this, &HybridVolumePanel::applyIsosurfaces);
  connect(stepSlider_, &QSlider::valueChanged, this, &HybridVolumePanel::stepFromSlider);
  connect(step_, &QDoubleSpinBox::valueChanged, this, [this](double v) { context_.setVolumeStep(v); });
  connect(stepDefault, &QPushButton::clicked, this, [this] { context_.setVolumeStep(0.0); });
  showScaleValue();
  volumeChanged();
}

double HybridVolumePanel::opacityScale() const {
  // A loaded scale holds until the slider moves off its step.
  if (exactScale_ && logPosition(*exactScale_, kMinScale, kMaxScale) == opacity_->value()) return *exactScale_;
  return logAt(opacity_->value(), kMinScale, kMaxScale);
}

void HybridVolumePanel::showScaleValue() {
  opacityValue_->setText(QStringLiteral("%1×").arg(opacityScale(), 0, 'f', 2));
}

// ---- the volume and its transfer function ---------------------------------------------------

void HybridVolumePanel::showVolumeChoice() {
  const QSignalBlocker block(volumeChoice_);
  const QStringList names = context_.hasScene() ? context_.volumeNames() : QStringList();
  setItems(volumeChoice_, names);
  volumeChoice_->setCurrentIndex(context_.hasScene() ? context_.currentVolume() : -1);
  volumeRow_->setVisible(names.size() > 1);
}

void HybridVolumePanel::showFieldChoice() {
  const QSignalBlocker block(fieldChoice_);
  const QStringList fields = context_.hasScene() ? context_.volumeFields() : QStringList();
  setItems(fieldChoice_, fields);
  fieldChoice_->setCurrentIndex(fields.indexOf(context_.hasScene() ? context_.volumeField() : QString()));
  fieldRow_->setVisible(fields.size() > 1);
  const bool loading = context_.hasScene() && context_.volumeFieldLoading();
  fieldChoice_->setEnabled(!loading);
  const QString error = context_.hasScene() ? context_.volumeFieldError() : QString();
  fieldNote_->setText(loading ? tr("Reading the field…") : error);
  fieldNote_->setStyleSheet(loading ? QString() : QStringLiteral("color: #b00020;"));
  fieldNote_->setVisible(loading || !error.isEmpty());
}

void HybridVolumePanel::volumeChanged() {
  showVolumeChoice();
  showFieldChoice();
  const bool has = context_.hasScene() && context_.hasVolume();
  controls_->setEnabled(has);
  show_->setEnabled(has);
  if (!has) {
    sceneKey_.clear();
    editor_->setPoints({});
    editor_->setHistogram({});
    histogramKey_.clear();
    showSelectedPoint();
    // No step or transfer strip of a volume no longer there (the last one's stayed; a bug hunt).
    {
      const QSignalBlocker block(step_);
      step_->setSpecialValueText(tr("—"));
      step_->setValue(step_->minimum());
    }
    preview_->clear();
    info_->setText(tr("The scene has no volume: open a .vti, .vtk, .mhd/.mha, .nrrd, .inr or .vdb file, or @volume."));
    showState();
    return;
  }
  const glm::ivec3 d = context_.volumeDims();
  const mfr::TransferFunction loaded = context_.loadedTransferFunction();
  // The volume's index too: two volumes alike in name, grid and function keep states of their own.
  QString key = QStringLiteral("%1|%2|%3x%4x%5|%6")
                    .arg(context_.currentVolume())
                    .arg(context_.volumeName())
                    .arg(d.x)
                    .arg(d.y)
                    .arg(d.z)
                    .arg(loaded.unitDistance, 0, 'g', 17);
  for (const mfr::TransferPoint& p : loaded.points) key += QStringLiteral("|%1").arg(p.value, 0, 'g', 17);
  // Another volume, or a function set elsewhere (a session, another plugin): Custom from it,
  // unless it is a volume of this scene the panel set up before and its function is still the
  // one the panel set: then the panel's state of that volume again.
  if (key != sceneKey_ || !sameTransfer(context_.transferFunction(), applied_)) {
    if (volumeStatesScene_ != context_.sceneSerial()) {
      volumeStates_.clear();
      volumeStatesScene_ = context_.sceneSerial();
    } else if (!sceneKey_.isEmpty() && key != sceneKey_) {
      volumeStates_.insert(sceneKey_, VolumeState{base_, applied_, preset_->currentData().toString(), windowLow_,
                                                  windowHigh_, opacity_->value(), exactScale_});
    }
    sceneKey_ = key;
    const auto saved = volumeStates_.constFind(key);
    if (saved != volumeStates_.constEnd() && sameTransfer(context_.transferFunction(), saved->applied)) {
      base_ = saved->base;
      applied_ = saved->applied;
      windowLow_ = saved->windowLow;
      windowHigh_ = saved->windowHigh;
      exactScale_ = saved->exactScale;
      const QSignalBlocker blockPreset(preset_), blockMin(windowMin_), blockMax(windowMax_), blockOpacity(opacity_);
      preset_->setCurrentIndex(preset_->findData(saved->preset));
      windowMin_->setValue(windowLow_);
      windowMax_->setValue(windowHigh_);
      opacity_->setValue(saved->opacityPosition);
      showScaleValue();
    } else {
      resetToCurrent();
    }
  }
  {
    const QSignalBlocker blockShade(shade_);
    shade_->setChecked(context_.volumeShading());
  }
  showFunction();
  showStep();
  showState();
  showInfo();
  showIsosurfaces();
}

// ---- isosurfaces ----------------------------------------------------------------------------

void HybridVolumePanel::showIsosurfaces() {
  const std::vector<double> values = context_.isosurfaceValues();
  QStringList texts;
  for (const double v : values) texts << QString::number(v, 'g', 8);
  if (isoError_.isEmpty()) isoValues_->setText(texts.join(QStringLiteral(", ")));
  if (!values.empty()) {
    const QSignalBlocker block(isoOpacity_);
    isoOpacity_->setValue(context_.isosurfaceOpacity());
  }
  const glm::dvec2 range = context_.volumeValueRange();
  // An example from this volume's values (a third and two thirds of the way), not a fixed one.
  isoValues_->setPlaceholderText(tr("values, e.g. %1, %2")
                                     .arg(range.x + (range.y - range.x) / 3.0, 0, 'g', 3)
                                     .arg(range.x + 2.0 * (range.y - range.x) / 3.0, 0, 'g', 3));
  isoNote_->setStyleSheet(isoError_.isEmpty() ? QString() : QStringLiteral("color: #b00020;"));
  isoNote_->setText(!isoError_.isEmpty() ? isoError_
                    : values.empty()
                        ? tr("Values inside %1 … %2").arg(range.x, 0, 'g', 6).arg(range.y, 0, 'g', 6)
                        : (values.size() == 1 ? tr("1 isosurface, in the scene tree as a part")
                                              : tr("%1 isosurfaces, in the scene tree as parts").arg(values.size())));
}

void HybridVolumePanel::applyIsosurfaces() {
  if (!context_.hasScene() || !context_.hasVolume()) return;
  std::vector<double> values;
  isoError_.clear();
  for (const QString& item :
       isoValues_->text().split(QRegularExpression(QStringLiteral("[,;\\s]+")), Qt::SkipEmptyParts)) {
    bool ok = false;
    const double v = item.toDouble(&ok);
    if (!ok) {
      isoError_ = tr("'%1' is not a number").arg(item);
      showIsosurfaces();
      return;
    }
    values.push_back(v);
  }
  const bool wasShown = show_->isChecked();
  isoError_ = context_.setIsosurfaces(values, isoOpacity_->value());
  // Making them hid the volume: give back the method and operation the Show switch had replaced.
  if (isoError_.isEmpty() && wasShown && !context_.volumeVisible()) setShow(false);
  showIsosurfaces();
}

void HybridVolumePanel::resetToCurrent() {
  base_ = context_.transferFunction();
  applied_ = base_;
  const QSignalBlocker blockPreset(preset_), blockMin(windowMin_), blockMax(windowMax_), blockOpacity(opacity_);
  preset_->setCurrentIndex(preset_->findData(kCustom));
  if (!base_.points.empty()) {
    const double span = std::max(std::abs(base_.high() - base_.low()), 1e-12);
    for (QDoubleSpinBox* box : {windowMin_, windowMax_})
      box->setSingleStep(std::pow(10.0, std::floor(std::log10(span)) - 1.0));
    windowLow_ = base_.low();
    windowHigh_ = base_.high();
    windowMin_->setValue(windowLow_);
    windowMax_->setValue(windowHigh_);
    // A function that is a preset over its own range — a scene file's {"preset", "range"}, an
    // InVesalius project's "bone" over its saved window — shows as that preset, not as Custom.
    for (const QString& name : context_.transferPresetNames())
      if (sameTransfer(context_.transferPreset(name, windowLow_, windowHigh_, base_.unitDistance), base_)) {
        preset_->setCurrentIndex(preset_->findData(name));
        break;
      }
  }
  exactScale_.reset();
  opacity_->setValue(logPosition(1.0, kMinScale, kMaxScale));
  showScaleValue();
  showFunction();
}

mfr::TransferFunction HybridVolumePanel::composed() const {
  const double lo = windowLow_, hi = windowHigh_;
  const double unit = base_.unitDistance / opacityScale();
  const QString mode = preset_->currentData().toString();
  if (mode != kCustom) return context_.transferPreset(mode, lo, hi, unit);
  mfr::TransferFunction t = base_;
  t.unitDistance = unit;
  // Points already spanning the window (the editor's, the loaded ones) stay exactly as they are.
  if (base_.points.size() >= 2 && base_.high() > base_.low() && (base_.low() != lo || base_.high() != hi)) {
    const double from = base_.low(), span = base_.high() - base_.low();
    for (mfr::TransferPoint& p : t.points) p.value = lo + (p.value - from) / span * (hi - lo);
  }
  return t;
}

void HybridVolumePanel::applyTransfer() {
  if (!context_.hasVolume()) return;
  QString reason;
  if (!(windowLow_ < windowHigh_)) {
    reason = tr("window: the minimum must be below the maximum");
  } else {
    const mfr::TransferFunction t = composed();
    applied_ = t;  // before the call: volumeChanged must see it as the panel's own
    reason = context_.setTransferFunction(t);
    if (!reason.isEmpty()) applied_ = context_.transferFunction();
  }
  error_->setText(reason);
  error_->setVisible(!reason.isEmpty());
  showFunction();
}

void HybridVolumePanel::showFunction() {
  showPreview();
  showEditor();
  showSelectedPoint();
}

void HybridVolumePanel::showEditor() {
  const mfr::TransferFunction t = context_.transferFunction();
  editor_->setPoints(t.points);
  if (t.points.size() < 2 || !(t.high() > t.low())) return;
  // One pass over the grid: only for another volume or range, not for each edit of the points.
  const QString key = QStringLiteral("%1|%2|%3").arg(sceneKey_).arg(t.low(), 0, 'g', 17).arg(t.high(), 0, 'g', 17);
  if (key == histogramKey_) return;
  histogramKey_ = key;
  editor_->setHistogram(context_.volumeHistogram(t.low(), t.high(), TransferFunctionEditor::kHistogramBins));
}

void HybridVolumePanel::showSelectedPoint() {
  const int index = editor_->selectedPoint();
  const std::vector<mfr::TransferPoint>& points = editor_->points();
  const bool has = index >= 0 && index < static_cast<int>(points.size());
  pointFields_->setEnabled(has);
  const QSignalBlocker blockValue(pointValue_), blockOpacity(pointOpacity_), blockRed(pointRed_),
      blockGreen(pointGreen_), blockBlue(pointBlue_);
  if (!has) {
    for (QDoubleSpinBox* box : {pointValue_, pointOpacity_, pointRed_, pointGreen_, pointBlue_}) box->setValue(0.0);
    pointColor_->setStyleSheet(QString());
    return;
  }
  const mfr::TransferPoint& p = points[static_cast<std::size_t>(index)];
  // The end points' values are the window's.
  pointValue_->setEnabled(index > 0 && index + 1 < static_cast<int>(points.size()));
  const double span = points.back().value - points.front().value;
  pointValue_->setSingleStep(std::pow(10.0, std::floor(std::log10(std::max(span, 1e-12))) - 2.0));
  pointValue_->setValue(p.value);
  pointOpacity_->setValue(p.color.a);
  pointRed_->setValue(p.color.r);
  pointGreen_->setValue(p.color.g);
  pointBlue_->setValue(p.color.b);
  pointColor_->setStyleSheet(
      QStringLiteral("background-color: %1;").arg(QColor::fromRgbF(p.color.r, p.color.g, p.color.b).name()));
}

void HybridVolumePanel::editSelectedPoint() {
  const int index = editor_->selectedPoint();
  if (index < 0 || index >= static_cast<int>(editor_->points().size())) return;
  const QObject* from = sender();
  const mfr::TransferPoint p = editor_->points()[static_cast<std::size_t>(index)];
  // Only the field the user changed: the others show rounded values and would round the point.
  if (from == pointValue_ || from == pointOpacity_) {
    editor_->movePoint(index, from == pointValue_ ? pointValue_->value() : p.value,
                       from == pointOpacity_ ? pointOpacity_->value() : p.color.a);
  } else {
    glm::vec3 rgb(p.color);
    if (from == pointRed_) rgb.r = static_cast<float>(pointRed_->value());
    if (from == pointGreen_) rgb.g = static_cast<float>(pointGreen_->value());
    if (from == pointBlue_) rgb.b = static_cast<float>(pointBlue_->value());
    editor_->setPointColor(index, rgb);
  }
  showSelectedPoint();  // a clamped value shows as applied
}

void HybridVolumePanel::applyEditor() {
  if (!context_.hasVolume()) return;
  // The edited points become Custom's own; their ends are the function's range, the window.
  base_.points = editor_->points();
  windowLow_ = base_.low();
  windowHigh_ = base_.high();
  {
    const QSignalBlocker blockPreset(preset_), blockMin(windowMin_), blockMax(windowMax_);
    preset_->setCurrentIndex(preset_->findData(kCustom));
    windowMin_->setValue(windowLow_);
    windowMax_->setValue(windowHigh_);
  }
  applyTransfer();
}

void HybridVolumePanel::showPreview() {
  const mfr::TransferFunction t = context_.transferFunction();
  const std::vector<glm::vec4> table = context_.transferTable(t);
  constexpr int kHeight = 28;
  QPixmap pixmap(256, kHeight);
  pixmap.fill(Qt::white);
  if (!table.empty()) {
    QPainter painter(&pixmap);
    const int n = static_cast<int>(table.size());
    QPolygonF curve;
    for (int x = 0; x < 256; ++x) {
      const glm::vec4 e = table[static_cast<std::size_t>(x * n / 256)];
      const double a = 1.0 - std::exp(-static_cast<double>(e.w) * t.unitDistance);
      for (int y = 0; y < kHeight; y += 7) {
        const bool dark = ((x / 7) + (y / 7)) % 2 == 0;
        const double bg = dark ? 0.6 : 0.9;
        const auto channel = [&](float c) { return static_cast<int>(std::lround(255.0 * (a * c + (1.0 - a) * bg))); };
        painter.fillRect(x, y, 1, 7, QColor(channel(e.r), channel(e.g), channel(e.b)));
      }
      curve << QPointF(x, (kHeight - 1) * (1.0 - a));
    }
    painter.setPen(QPen(Qt::black, 1));
    painter.drawPolyline(curve);
  }
  preview_->setPixmap(pixmap);
}

// ---- show switch ---------------------------------------------------------------------------

void HybridVolumePanel::setShow(bool on) {
  if (!context_.hasVolume()) {
    showState();
    return;
  }
  if (!on) {
    context_.setVolumeVisible(false);
    // Other volumes still drawn keep the operation volume.
    if (context_.visibleVolumeCount() > 0) {
      showState();
      return;
    }
    if (!previousMethod_.isEmpty() && context_.method() == QLatin1String(kVolumeMethod))
      context_.setMethod(previousMethod_);
    if (context_.operation() == kVolume)
      context_.setOperation(previousOperation_.isEmpty() ? QStringLiteral("auto") : previousOperation_);
    previousMethod_.clear();
    previousOperation_.clear();
    showState();
    return;
  }
  const QString method = context_.method(), operation = context_.operation();
  context_.setVolumeVisible(true);
  if (context_.effectiveOperation() != kVolume) {
    if (!context_.supportsOperation(method, kVolume)) {
      previousMethod_ = method;
      context_.setMethod(QLatin1String(kVolumeMethod));
    }
    if (context_.effectiveOperation() != kVolume) {
      previousOperation_ = operation;
      context_.setOperation(kVolume);
    }
  }
  showState();
}

void HybridVolumePanel::showState() {
  const bool on = context_.hasVolume() && context_.volumeVisible() && context_.effectiveOperation() == kVolume;
  {
    const QSignalBlocker block(show_);
    show_->setChecked(on);
  }
  const QString method = context_.method();
  const bool refused = context_.operation() == kVolume && !context_.supportsOperation(method, kVolume);
  note_->setText(refused ? tr("%1 keeps no sorted lists and cannot composite the volume: choose an A-buffer, a "
                              "k-buffer or the oracle.")
                               .arg(method)
                         : QString());
  note_->setVisible(refused);
}

// ---- step ----------------------------------------------------------------------------------

void HybridVolumePanel::showStep() {
  const double fallback = context_.volumeStepDefault();
  const double value = context_.volumeStep() > 0.0 ? context_.volumeStep() : fallback;
  const QSignalBlocker blockSlider(stepSlider_), blockBox(step_);
  if (fallback > 0.0) stepSlider_->setValue(logPosition(value / fallback, kMinStepFactor, kMaxStepFactor));
  step_->setSingleStep(std::max(1.0e-6, fallback / 10.0));
  step_->setSpecialValueText(QString());
  step_->setValue(value);
}

void HybridVolumePanel::stepFromSlider(int position) {
  const double fallback = context_.volumeStepDefault();
  if (fallback > 0.0) context_.setVolumeStep(logAt(position, kMinStepFactor, kMaxStepFactor) * fallback);
}

void HybridVolumePanel::showInfo() {
  if (!context_.hasVolume()) return;
  const glm::ivec3 d = context_.volumeDims();
  const glm::dvec3 s = context_.volumeSpacing();
  const glm::dvec2 r = context_.volumeValueRange();
  QStringList lines;
  lines << tr("%1: %2×%3×%4 points, spacing %5 × %6 × %7")
               .arg(context_.volumeName())
               .arg(d.x)
               .arg(d.y)
               .arg(d.z)
               .arg(s.x, 0, 'g', 4)
               .arg(s.y, 0, 'g', 4)
               .arg(s.z, 0, 'g', 4);
  if (const QStringList fields = context_.volumeFields(); !fields.isEmpty())
    lines << tr("field %1 (of %2)").arg(context_.volumeField(), fields.join(QStringLiteral(", ")));
  lines << tr("values %1 … %2").arg(r.x, 0, 'g', 6).arg(r.y, 0, 'g', 6);  // as the isosurface hint shows them
  // No frame on screen: not the numbers of the last one drawn (a review of interface 1.14).
  if (!context_.frameError().isEmpty()) {
    lines << tr("last frame: none (the view could not draw)");
    info_->setText(lines.join(QLatin1Char('\n')));
    return;
  }
  QString step, bytes, sharedBytes;
  for (const auto& [name, value] : context_.stats().notes) {
    if (name == "volume step") step = QString::fromStdString(value);
    if (name == "volume (bytes)") bytes = QString::fromStdString(value);
    if (name == "volume grid held by the scene (bytes)") sharedBytes = QString::fromStdString(value);
  }
  if (!step.isEmpty()) {
    QString line = tr("last frame: step %1").arg(step.toDouble(), 0, 'g', 5);
    if (!bytes.isEmpty()) line += tr(", %1 on the GPU").arg(bytesText(bytes.toDouble()));
    if (!sharedBytes.isEmpty())
      line += tr(" (+ its grid, %1, held by the surfaces it colours)").arg(bytesText(sharedBytes.toDouble()));
    lines << line;
  } else {
    lines << tr("last frame: volume not drawn (step %1)")
                 .arg(context_.volumeStep() > 0.0 ? context_.volumeStep() : context_.volumeStepDefault(), 0, 'g', 5);
  }
  info_->setText(lines.join(QLatin1Char('\n')));
}

// ---- settings -------------------------------------------------------------------------------

// What a scene without a volume saves: the same keys and types, fixed values (the panel's state
// there is whatever the last volume left), so that such a session's settings are recognised as
// no news when it is opened again.
QJsonObject HybridVolumePanel::noVolumeSettings() const {
  return {{QStringLiteral("volume"), -1},
          {QStringLiteral("show"), false},
          {QStringLiteral("preset"), preset_->count() > 0 ? preset_->itemData(0).toString() : QString()},
          {QStringLiteral("window"), QJsonArray{0.0, 1.0}},
          {QStringLiteral("opacity_scale"), 1.0},
          {QStringLiteral("shading"), false},
          {QStringLiteral("base"), transferToJson(mfr::TransferFunction{})},
          {QStringLiteral("step"), 0.0},
          {QStringLiteral("previous_operation"), QString()},
          {QStringLiteral("previous_method"), QString()}};
}

QJsonObject HybridVolumePanel::saveSettings() const {
  if (!context_.hasVolume()) return noVolumeSettings();
  return {{QStringLiteral("volume"), context_.currentVolume()},
          {QStringLiteral("show"), show_->isChecked()},
          {QStringLiteral("preset"), preset_->currentData().toString()},
          // A window refused (its minimum not below its maximum) is not what is drawn: the
          // drawn function's range is (a refused one was saved, then refused on reload).
          {QStringLiteral("window"), windowLow_ < windowHigh_ ? QJsonArray{windowLow_, windowHigh_}
                                                              : QJsonArray{applied_.low(), applied_.high()}},
          {QStringLiteral("opacity_scale"), opacityScale()},
          {QStringLiteral("shading"), shade_->isChecked()},
          {QStringLiteral("base"), transferToJson(base_)},
          {QStringLiteral("step"), context_.volumeStep()},
          {QStringLiteral("previous_operation"), previousOperation_},
          {QStringLiteral("previous_method"), previousMethod_}};
}

void HybridVolumePanel::loadSettings(const QJsonObject& settings) {
  // Values taken other than as given are notes (they were defaults or clamps without a word).
  const auto note = [&](const QString& text) { context_.note(QStringLiteral("hybridvolume: ") + text); };
  if (!context_.hasScene()) return;
  // Settings for a scene without a volume were dropped without a word (a bug hunt); those the
  // panel itself saves there (its defaults, in every session of such a scene) are no news.
  if (!context_.hasVolume()) {
    const QJsonObject own = noVolumeSettings();
    bool same = true;
    for (auto it = settings.begin(); it != settings.end(); ++it) same = same && own.value(it.key()) == it.value();
    if (!same) note(tr("the scene has no volume (the settings are left out)"));
    return;
  }
  // The volume the panel showed (absent in sessions of one volume): its controls get the settings.
  const QJsonValue given = settings.value(QStringLiteral("volume"));
  const double asked = given.toDouble(context_.currentVolume());
  const int volume = given.isUndefined() || (given.isDouble() && asked == std::floor(asked) && std::abs(asked) < 1e9)
                         ? static_cast<int>(asked)
                         : -1;  // 1.5 was read as the current volume
  if (volume < 0 || volume >= context_.volumeCount())
    note(tr("volume %1: the scene has %2 (volume %3 is shown)")
             .arg(given.isDouble() ? QString::number(asked) : QStringLiteral("?"))
             .arg(context_.volumeCount())
             .arg(context_.currentVolume()));
  else
    context_.setCurrentVolume(volume);
  volumeChanged();  // this scene's volume (sessions load settings after their own state)
  previousOperation_ = settings.value(QStringLiteral("previous_operation")).toString();
  previousMethod_ = settings.value(QStringLiteral("previous_method")).toString();
  QString baseError;
  const mfr::TransferFunction base =
      transferFromJson(settings.value(QStringLiteral("base")).toObject(), base_.unitDistance, baseError);
  if (!baseError.isEmpty())
    note(tr("base.%1 (the volume's own function is kept)").arg(baseError));
  else if (!context_.transferTable(base).empty())
    base_ = base;
  else if (settings.contains(QStringLiteral("base")))
    note(tr("base: not a transfer function the volume can use (the volume's own is kept)"));
  {
    const QSignalBlocker blockPreset(preset_), blockMin(windowMin_), blockMax(windowMax_), blockOpacity(opacity_);
    const QString presetName = settings.value(QStringLiteral("preset")).toString(kCustom);
    const int preset = preset_->findData(presetName);
    if (preset < 0) note(tr("preset '%1': no such preset (custom is used)").arg(presetName));
    preset_->setCurrentIndex(preset >= 0 ? preset : preset_->findData(kCustom));
    const QJsonArray window = settings.value(QStringLiteral("window")).toArray();
    if (settings.contains(QStringLiteral("window")) && window.size() != 2)
      note(tr("window: expected [low, high] (the window is kept)"));
    if (window.size() == 2 && !(window[0].toDouble() < window[1].toDouble()))
      note(tr("window [%1, %2]: low must be below high (the window is kept)")
               .arg(window[0].toDouble())
               .arg(window[1].toDouble()));
    else if (window.size() == 2) {
      windowLow_ = window[0].toDouble();
      windowHigh_ = window[1].toDouble();
      windowMin_->setValue(windowLow_);
      windowMax_->setValue(windowHigh_);
    }
    const double scale = settings.value(QStringLiteral("opacity_scale")).toDouble(1.0);
    if (!(scale >= kMinScale && scale <= kMaxScale))
      note(
          tr("opacity_scale %1 is outside %2 … %3 (the nearest end is used)").arg(scale).arg(kMinScale).arg(kMaxScale));
    opacity_->setValue(logPosition(scale, kMinScale, kMaxScale));
    // Exactly as given, not the slider's nearest step (2 drew as 2.00373; a bug hunt).
    exactScale_ = std::clamp(scale, kMinScale, kMaxScale);
    showScaleValue();
  }
  applyTransfer();  // the session's own function again (no change), or --plugin-settings' one
  // A function the viewer refuses was shown in the panel only: a scripted run drew the old one
  // with exit 0 (a bug hunt: window [0, 1e308]). A note, as the other settings taken otherwise.
  if (!error_->text().isEmpty()) note(tr("%1 (the function is kept)").arg(error_->text()));
  if (settings.contains(QStringLiteral("shading")))
    context_.setVolumeShading(settings.value(QStringLiteral("shading")).toBool());
  if (settings.contains(QStringLiteral("step"))) {
    // 0 is the default step; a negative one was ignored without a word.
    const double step = settings.value(QStringLiteral("step")).toDouble();
    if (step >= 0.0)
      context_.setVolumeStep(step);
    else
      note(tr("step %1: must be a positive length in scene units, or 0 for the default (the step is kept)").arg(step));
  }
  if (settings.contains(QStringLiteral("show")) &&
      settings.value(QStringLiteral("show")).toBool() != show_->isChecked())
    setShow(settings.value(QStringLiteral("show")).toBool());
  showState();
}
