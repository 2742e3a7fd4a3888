#include "method_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QVBoxLayout>

#include <cmath>

#include "viewer_model.hpp"

namespace {

// A float parameter's editor: the shortest text that reads back as the value, in the locale's
// notation, exponents included, instead of three decimals — mboit's moment bias of the paper, 5e-7, showed and was
// taken as 0.000, a different setting from its default −1 (a bug hunt).
class FloatParamBox : public QDoubleSpinBox {
 public:
  FloatParamBox() { setDecimals(15); }  // values are not rounded to the text's few digits
  [[nodiscard]] QString textFromValue(double value) const override {
    return locale().toString(value, 'g', QLocale::FloatingPointShortest);  // round-trips: Enter changes nothing
  }
  [[nodiscard]] double valueFromText(const QString& text) const override { return locale().toDouble(text.trimmed()); }
  QValidator::State validate(QString& text, int&) const override {
    bool ok = false;
    const double value = locale().toDouble(text.trimmed(), &ok);
    if (ok && value >= minimum() && value <= maximum()) return QValidator::Acceptable;
    return QValidator::Intermediate;  // "5e-", "-" on the way to a number
  }
};

// Float parameters as text: round-trips the spin box value without trailing noise.
std::string floatText(double value) {
  return QString::number(value, 'g', 10).toStdString();
}

}  // namespace

MethodPanel::MethodPanel(ViewerModel& model, int side, QWidget* parent) : QWidget(parent), model_(model), side_(side) {
  auto* layout = new QVBoxLayout(this);
  auto* top = new QFormLayout;
  methodCombo_ = new QComboBox;
  methodCombo_->setObjectName(objectName(QStringLiteral("methodCombo")));
  for (const QString& name : model_.methodNames()) {
    const mfr::MethodInfo* info = model_.methodInfo(name);
    const QString cpuTitle = name == QLatin1String("oracle") ? tr("exact CPU reference") : tr("CPU method");
    methodCombo_->addItem(info ? QStringLiteral("%1 — %2").arg(name, QString::fromStdString(info->title))
                               : QStringLiteral("%1 — %2").arg(name, cpuTitle),
                          name);
  }
  // Long method titles must not dictate the dock's width.
  methodCombo_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  methodCombo_->setMinimumContentsLength(16);
  operationCombo_ = new QComboBox;
  operationCombo_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  operationCombo_->setMinimumContentsLength(16);
  operationCombo_->setObjectName(objectName(QStringLiteral("operationCombo")));
  operationCombo_->addItem(tr("auto — the method's own (hybrid for the budget methods)"), QStringLiteral("auto"));
  operationCombo_->addItem(tr("oit — composite \"over\""), QStringLiteral("oit"));
  operationCombo_->addItem(tr("hybrid — exact core + averaged tail"), QStringLiteral("hybrid"));
  operationCombo_->addItem(tr("csg — the scene's CSG tree as opaque solids"), QStringLiteral("csg"));
  operationCombo_->addItem(tr("zthickness — blend surfaces closer than a thickness"), QStringLiteral("zthickness"));
  operationCombo_->addItem(tr("volume — the scene's volume between the sorted surfaces"), QStringLiteral("volume"));
  // Operation zthickness: the slab thickness (scene units, shared by both panes); the minimum, 0,
  // reads "default" and follows the scene (1 % of its diagonal).
  thickness_ = new QDoubleSpinBox;
  thickness_->setObjectName(objectName(QStringLiteral("zThickness")));
  thickness_->setDecimals(6);
  thickness_->setRange(0.0, 1.0e9);
  thickness_->setKeyboardTracking(false);
  thickness_->setToolTip(
      tr("Each fragment is a slab this thick (scene units) behind its surface: surfaces closer than this "
         "blend without z-fighting, surfaces further apart composite \"over\". 0: 1 % of the scene's diagonal."));
  // Operation volume: the ray-march step (scene units, shared by both panes); 0 reads "default"
  // and follows the volume (half its smallest grid spacing).
  step_ = new QDoubleSpinBox;
  step_->setObjectName(objectName(QStringLiteral("volumeStep")));
  step_->setDecimals(6);
  step_->setRange(0.0, 1.0e9);
  step_->setKeyboardTracking(false);
  step_->setToolTip(
      tr("Operation volume: distance between the volume's samples along each ray, in scene units "
         "(smaller: more exact and slower). 0: half the volume's smallest grid spacing."));
  auto* stepDefault = new QPushButton(tr("Default"));
  stepDefault->setObjectName(objectName(QStringLiteral("volumeStepDefault")));
  stepDefault->setToolTip(tr("Half the volume's smallest grid spacing"));
  stepRow_ = new QWidget;
  auto* stepLayout = new QHBoxLayout(stepRow_);
  stepLayout->setContentsMargins(0, 0, 0, 0);
  stepLayout->addWidget(step_, 1);
  stepLayout->addWidget(stepDefault);
  top->addRow(tr("Method"), methodCombo_);
  top->addRow(tr("Operation"), operationCombo_);
  top->addRow(tr("Thickness"), thickness_);
  top->addRow(tr("Step"), stepRow_);
  topLayout_ = top;
  layout->addLayout(top);

  description_ = new QLabel;
  description_->setWordWrap(true);
  description_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  description_->setStyleSheet(QStringLiteral("color: palette(mid);"));
  layout->addWidget(description_);

  paramsBox_ = new QWidget;
  paramsLayout_ = new QFormLayout(paramsBox_);
  paramsLayout_->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(paramsBox_);

  auto* reset = new QPushButton(tr("Reset to defaults"));
  connect(reset, &QPushButton::clicked, this, [this] {
    auto all = model_.allParamsOf(side_);
    all.erase(model_.methodOf(side_).toStdString());
    model_.setAllParamsOf(side_, std::move(all));
  });
  layout->addWidget(reset, 0, Qt::AlignRight);
  layout->addStretch(1);

  connect(methodCombo_, &QComboBox::currentIndexChanged, this,
          [this](int index) { model_.setMethodOf(side_, methodCombo_->itemData(index).toString()); });
  connect(operationCombo_, &QComboBox::currentIndexChanged, this,
          [this](int index) { model_.setOperationOf(side_, operationCombo_->itemData(index).toString()); });
  connect(thickness_, &QDoubleSpinBox::valueChanged, this, [this](double v) { model_.setZThickness(v); });
  connect(step_, &QDoubleSpinBox::valueChanged, this, [this](double v) { model_.setVolumeStep(v); });
  connect(stepDefault, &QPushButton::clicked, this, [this] { model_.setVolumeStep(0.0); });
  connect(&model_, &ViewerModel::volumeChanged, this, [this] {
    syncMethodCombo();  // what "auto" runs follows the volume's visibility
    showStep();
    showParameterValues();  // and so do the defaults that depend on it
  });
  connect(&model_, &ViewerModel::zThicknessChanged, this, &MethodPanel::showThickness);
  connect(&model_, &ViewerModel::sceneChanged, this, &MethodPanel::showThickness);  // the default follows the scene
  connect(&model_, &ViewerModel::sideChanged, this, [this](int changed) {
    if (changed != side_) return;
    syncMethodCombo();
    if (model_.methodOf(side_) != shownMethod_)
      rebuildParameters();
    else
      showParameterValues();
  });
  syncMethodCombo();
  rebuildParameters();
  showThickness();
  showStep();
}

void MethodPanel::showStep() {
  const QSignalBlocker block(step_);
  const double fallback = model_.volumeStepDefault();
  step_->setSpecialValueText(tr("default (%1)").arg(fallback, 0, 'g', 4));
  step_->setSingleStep(std::max(1.0e-6, fallback / 10.0));
  step_->setValue(model_.volumeStep());
  topLayout_->setRowVisible(stepRow_, model_.effectiveOperationOf(side_) == QLatin1String("volume"));
}

void MethodPanel::showThickness() {
  const QSignalBlocker block(thickness_);
  const double fallback = model_.zThicknessDefault();
  thickness_->setSpecialValueText(tr("default (%1)").arg(fallback, 0, 'g', 4));
  thickness_->setSingleStep(std::max(1.0e-6, fallback / 10.0));
  thickness_->setValue(model_.zThickness());
  topLayout_->setRowVisible(thickness_, model_.effectiveOperationOf(side_) == QLatin1String("zthickness"));
}

QString MethodPanel::objectName(const QString& base) const {
  return side_ == 0 ? base : base + QStringLiteral("B");
}

void MethodPanel::syncMethodCombo() {
  const QSignalBlocker block(methodCombo_), blockOp(operationCombo_);
  methodCombo_->setCurrentIndex(methodCombo_->findData(model_.methodOf(side_)));
  operationCombo_->setCurrentIndex(operationCombo_->findData(model_.operationOf(side_)));
  // What "auto" runs now (a scene with a visible volume: "volume" for the methods with sorted lists).
  operationCombo_->setItemText(
      0, tr("auto — the method's own (now: %1)").arg(model_.resolvedOperation(side_, QStringLiteral("auto"))));
  // As the renderer resolves "auto" (kbuffer-zmerge's own is zthickness: its thickness row was hidden; review 28).
  if (thickness_)
    topLayout_->setRowVisible(thickness_, model_.effectiveOperationOf(side_) == QLatin1String("zthickness"));
  if (stepRow_) topLayout_->setRowVisible(stepRow_, model_.effectiveOperationOf(side_) == QLatin1String("volume"));
}

void MethodPanel::rebuildParameters() {
  while (paramsLayout_->rowCount() > 0) paramsLayout_->removeRow(0);
  editors_.clear();
  shownMethod_ = model_.methodOf(side_);
  const mfr::MethodInfo* info = model_.methodInfo(shownMethod_);
  if (!info) {
    description_->setText(shownMethod_ == QLatin1String("oracle")
                              ? tr("Exact per-pixel fragment lists by CPU ray casting; the reference for every method.")
                              : tr("Computed on the CPU off the GUI thread, like the oracle."));
    return;
  }
  description_->setText(QString::fromStdString(info->paper));
  for (const mfr::ParamSpec& spec : info->params) {
    QWidget* editor = nullptr;
    const std::string name = spec.name;
    const auto set = [this, name](const std::string& value) { model_.setParamsOf(side_, {{name, value}}); };
    switch (spec.type) {
      case mfr::ParamSpec::Type::Int: {
        auto* box = new QSpinBox;
        box->setRange(static_cast<int>(spec.min), static_cast<int>(std::min(spec.max, 2.0e9)));
        box->setKeyboardTracking(false);  // re-render when typing is done, not per digit
        connect(box, &QSpinBox::valueChanged, this, [set](int v) { set(std::to_string(v)); });
        editor = box;
        break;
      }
      case mfr::ParamSpec::Type::Float: {
        auto* box = new FloatParamBox;
        box->setRange(spec.min, spec.max);
        box->setSingleStep(spec.max - spec.min > 10.0 ? 1.0 : 0.05);
        box->setKeyboardTracking(false);
        connect(box, &QDoubleSpinBox::valueChanged, this, [set](double v) { set(floatText(v)); });
        editor = box;
        break;
      }
      case mfr::ParamSpec::Type::Bool: {
        auto* box = new QCheckBox;
        connect(box, &QCheckBox::toggled, this, [set](bool v) { set(v ? "true" : "false"); });
        editor = box;
        break;
      }
      case mfr::ParamSpec::Type::Text: {  // a file path (dkb's weights): applied when editing ends
        auto* line = new QLineEdit;
        line->setPlaceholderText(tr("(built-in)"));
        connect(line, &QLineEdit::editingFinished, this, [set, line] { set(line->text().toStdString()); });
        editor = line;
        break;
      }
      case mfr::ParamSpec::Type::Choice: {
        auto* box = new QComboBox;
        for (const std::string& c : spec.choices) box->addItem(QString::fromStdString(c));
        connect(box, &QComboBox::currentTextChanged, this, [set](const QString& v) { set(v.toStdString()); });
        editor = box;
        break;
      }
    }
    if (!editor) continue;  // a parameter type this viewer has no widget for
    editor->setObjectName(objectName(QStringLiteral("param-") + QString::fromStdString(name) +
                                     (side_ == 0 ? QString() : QStringLiteral("-"))));
    editor->setToolTip(QString::fromStdString(spec.help));
    auto* label = new QLabel(QString::fromStdString(spec.label));
    label->setToolTip(QString::fromStdString(spec.help));
    paramsLayout_->addRow(label, editor);
    editors_[name] = editor;
  }
  showParameterValues();
}

void MethodPanel::showParameterValues() {
  const mfr::MethodInfo* info = model_.methodInfo(shownMethod_);
  if (!info) return;
  const auto values = model_.paramsOf(side_);
  for (const mfr::ParamSpec& spec : info->params) {
    const auto it = values.find(spec.name);
    // The default of the operation in force (fkb's tail and the exact tail are off outside hybrid).
    const QString value = QString::fromStdString(
        it != values.end() ? it->second : mfr::defaultValueFor(spec, model_.effectiveOperationOf(side_).toStdString()));
    const auto found = editors_.find(spec.name);
    if (found == editors_.end()) continue;
    QWidget* editor = found->second;
    const QSignalBlocker block(editor);
    if (auto* i = qobject_cast<QSpinBox*>(editor))
      i->setValue(value.toInt());
    else if (auto* d = qobject_cast<QDoubleSpinBox*>(editor))
      d->setValue(value.toDouble());
    else if (auto* b = qobject_cast<QCheckBox*>(editor))
      b->setChecked(value == QLatin1String("true") || value == QLatin1String("1"));
    else if (auto* c = qobject_cast<QComboBox*>(editor))
      c->setCurrentText(value);
    else if (auto* t = qobject_cast<QLineEdit*>(editor))
      t->setText(value);
  }
}
