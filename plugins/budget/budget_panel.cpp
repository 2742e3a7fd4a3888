#include "budget_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHideEvent>
#include <QLabel>
#include <QLocale>
#include <QProgressBar>
#include <QShowEvent>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

#include "histogram_widget.hpp"
#include "mfr/error.hpp"
#include "viewer_plugin.hpp"

namespace {

constexpr double kMiB = 1024.0 * 1024.0;
constexpr int kMaxCorrections = 3;
constexpr int kDefaultBudgetMiB = 16;
constexpr double kPoolMarginBytes = 1024;
// Quality is measured once the view has been still this long: it costs an exact CPU image, which
// a short pause between two camera moves should not start.
constexpr int kQualityDelayMs = 1200;
constexpr int kRobustnessSteps = 1000;

// A CPU method other than the oracle (e.g. optimal-k): computed when shown, off the GUI thread.
// Without ParamSpecs to read, it is given the budget as budget_mib like its GPU competitors.
bool isOnDemandCpuMethod(const ViewerContext& ctx, const QString& method) {
  return method != QLatin1String("oracle") && ctx.isCpuMethod(method);
}

const mfr::ParamSpec* findParam(const ViewerContext& ctx, const QString& method, const std::string& name) {
  if (const mfr::MethodInfo* info = ctx.methodInfo(method))
    for (const mfr::ParamSpec& spec : info->params)
      if (spec.name == name) return &spec;
  return nullptr;
}

QString mib(double bytes) {
  return QString::number(bytes / kMiB, 'f', bytes < 10 * kMiB ? 2 : 1);
}

std::string parameterValue(const ViewerContext& ctx, const std::string& name) {
  const auto values = ctx.params();
  if (const auto it = values.find(name); it != values.end()) return it->second;
  if (const mfr::MethodInfo* info = ctx.methodInfo(ctx.method()))
    for (const mfr::ParamSpec& spec : info->params)
      if (spec.name == name) return spec.defaultValue;
  return {};
}

}  // namespace

BudgetPanel::BudgetPanel(ViewerContext& context, QWidget* parent) : QWidget(parent), ctx_(context) {
  setObjectName(QStringLiteral("budgetPanel"));
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;
  methodCombo_ = new QComboBox;
  methodCombo_->setObjectName(QStringLiteral("budgetMethodCombo"));
  methodCombo_->setPlaceholderText(tr("(current method has no memory parameter)"));
  // From the registry (and mfrcore's CPU methods), never a fixed list.
  for (const QString& name : ctx_.methodNames()) {
    if (driverFor(name).knob == Knob::None) continue;
    methodCombo_->addItem(isOnDemandCpuMethod(ctx_, name) ? tr("%1 (CPU, on demand)").arg(name) : name, name);
  }
  form->addRow(tr("Method"), methodCombo_);

  auto* budgetRow = new QHBoxLayout;
  slider_ = new QSlider(Qt::Horizontal);
  slider_->setObjectName(QStringLiteral("budgetSlider"));
  slider_->setRange(1, 256);
  slider_->setValue(kDefaultBudgetMiB);
  slider_->setTickPosition(QSlider::TicksBelow);
  slider_->setTickInterval(32);
  spin_ = new QSpinBox;
  spin_->setObjectName(QStringLiteral("budgetSpin"));
  spin_->setRange(1, 4096);
  spin_->setSuffix(QStringLiteral(" MiB"));
  spin_->setValue(kDefaultBudgetMiB);
  spin_->setKeyboardTracking(false);
  budgetRow->addWidget(slider_, 1);
  budgetRow->addWidget(spin_);
  form->addRow(tr("Budget"), budgetRow);
  knobLabel_ = new QLabel;
  knobLabel_->setWordWrap(true);
  form->addRow(tr("Drives"), knobLabel_);

  // R_h of kplus-dynamic (and any method with a `robustness` parameter).
  robustnessRow_ = new QWidget;
  auto* robustnessLayout = new QHBoxLayout(robustnessRow_);
  robustnessLayout->setContentsMargins(0, 0, 0, 0);
  robustnessSlider_ = new QSlider(Qt::Horizontal);
  robustnessSlider_->setObjectName(QStringLiteral("budgetRobustnessSlider"));
  robustnessSlider_->setRange(0, kRobustnessSteps);
  robustness_ = new QDoubleSpinBox;
  robustness_->setObjectName(QStringLiteral("budgetRobustness"));
  robustness_->setDecimals(3);
  robustness_->setSingleStep(0.01);
  robustness_->setKeyboardTracking(false);
  robustnessLayout->addWidget(robustnessSlider_, 1);
  robustnessLayout->addWidget(robustness_);
  robustnessLabel_ = new QLabel(tr("Robustness R_h"));
  robustnessLabel_->setToolTip(tr("Fraction of the frame's fragments the chosen k should capture (within the budget)"));
  robustnessRow_->setToolTip(robustnessLabel_->toolTip());
  form->addRow(robustnessLabel_, robustnessRow_);
  layout->addLayout(form);

  auto* frameBox = new QGroupBox(tr("Last frame"));
  auto* frameForm = new QFormLayout(frameBox);
  memoryBar_ = new QProgressBar;
  memoryBar_->setObjectName(QStringLiteral("memoryBar"));
  memoryBar_->setRange(0, 1000);
  memoryBar_->setTextVisible(true);
  memoryLabel_ = new QLabel;
  capturedLabel_ = new QLabel;
  capturedLabel_->setObjectName(QStringLiteral("capturedLabel"));
  kLabel_ = new QLabel;
  exactLabel_ = new QLabel(tr("—"));
  exactLabel_->setObjectName(QStringLiteral("budgetExactAt"));
  exactLabel_->setToolTip(
      tr("The least budget at which this frame's image is exact (vkb, dkb: a one-fragment "
         "tail, and a final run of one colour, are exact: Σ max(1, n − m) slots suffice)"));
  // Each frame's numbers wrap rather than widen the dock: a wider dock narrows the view, and the
  // view draws its frame again at the new size (a slow method's whole cost, for a longer number).
  for (QLabel* l : {memoryLabel_, capturedLabel_, kLabel_, exactLabel_}) l->setWordWrap(true);
  frameForm->addRow(tr("Memory"), memoryBar_);
  frameForm->addRow(tr("Holding data"), memoryLabel_);
  frameForm->addRow(tr("Captured"), capturedLabel_);
  frameForm->addRow(tr("k"), kLabel_);
  frameForm->addRow(tr("Exact from"), exactLabel_);
  rmseLabel_ = new QLabel(tr("—"));
  rmseLabel_->setObjectName(QStringLiteral("budgetRmse"));
  flipLabel_ = new QLabel(tr("—"));
  rmseLabel_->setWordWrap(true);
  flipLabel_->setWordWrap(true);  // it may hold why the numbers were not computed
  flipLabel_->setObjectName(QStringLiteral("budgetFlip"));
  rmseLabel_->setToolTip(qualityToolTip(rmseLabel_, QString()));
  flipLabel_->setToolTip(qualityToolTip(flipLabel_, QString()));
  frameForm->addRow(tr("RMSE vs exact"), rmseLabel_);
  frameForm->addRow(tr("FLIP vs exact"), flipLabel_);
  kMapOverlay_ = new QCheckBox(tr("Show k(p) over the image"));
  kMapOverlay_->setObjectName(QStringLiteral("budgetKMapOverlay"));
  frameForm->addRow(kMapOverlay_);
  layout->addWidget(frameBox);

  histogram_ = new HistogramWidget;
  histogram_->setObjectName(QStringLiteral("depthHistogram"));
  layout->addWidget(histogram_, 1);

  histogramTimer_ = new QTimer(this);
  histogramTimer_->setSingleShot(true);
  histogramTimer_->setInterval(400);  // after the camera has come to rest
  connect(histogramTimer_, &QTimer::timeout, this, [this] { ctx_.requestDepthComplexity(); });
  connect(&ctx_, &ViewerContext::sceneChanged, histogramTimer_, qOverload<>(&QTimer::start));
  connect(&ctx_, &ViewerContext::viewChanged, histogramTimer_, qOverload<>(&QTimer::start));
  connect(&ctx_, &ViewerContext::depthComplexityReady, histogram_, &HistogramWidget::setHistogram);

  connect(slider_, &QSlider::valueChanged, this, [this](int v) { setBudget(v); });
  connect(spin_, &QSpinBox::valueChanged, this, [this](int v) { setBudget(v); });
  connect(methodCombo_, &QComboBox::activated, this,
          [this](int index) { ctx_.setMethod(methodCombo_->itemData(index).toString()); });
  connect(&ctx_, &ViewerContext::methodChanged, this, &BudgetPanel::methodChanged);
  connect(&ctx_, &ViewerContext::frameRendered, this, &BudgetPanel::frameRendered);
  connect(&ctx_, &ViewerContext::frameErrorChanged, this, [this] {
    showFrame();
    showQuality();
  });

  qualityTimer_ = new QTimer(this);
  qualityTimer_->setSingleShot(true);
  qualityTimer_->setInterval(kQualityDelayMs);
  connect(qualityTimer_, &QTimer::timeout, this, [this] {
    if (isVisible()) ctx_.requestFrameQuality();  // hidden panels cost nothing
  });

  connect(robustnessSlider_, &QSlider::valueChanged, this, [this](int v) {
    const double span = robustness_->maximum() - robustness_->minimum();
    robustness_->setValue(robustness_->minimum() + span * v / kRobustnessSteps);
  });
  connect(robustness_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    if (!findParam(ctx_, ctx_.method(), "robustness")) return;
    ctx_.setParams({{"robustness", QString::number(v, 'g', 6).toStdString()}});
  });
  connect(&ctx_, &ViewerContext::paramsChanged, this, &BudgetPanel::showRobustness);

  connect(kMapOverlay_, &QCheckBox::toggled, this,
          [this](bool on) { ctx_.setDataView(on ? DataView::Capacity : DataView::Image, on); });
  connect(&ctx_, &ViewerContext::dataViewChanged, this, [this] {
    const QSignalBlocker block(kMapOverlay_);
    kMapOverlay_->setChecked(ctx_.dataView() == DataView::Capacity && ctx_.dataViewOverImage());
  });
  methodChanged();
}

void BudgetPanel::showEvent(QShowEvent* event) {
  QWidget::showEvent(event);
  if (!qualityListened_)
    qualityListened_ = connect(&ctx_, &ViewerContext::frameQualityReady, this, &BudgetPanel::showQuality);
  qualityTimer_->start();  // the quality of the frame shown now
}

void BudgetPanel::hideEvent(QHideEvent* event) {
  QWidget::hideEvent(event);
  disconnect(qualityListened_);
  qualityListened_ = {};
}

int BudgetPanel::budgetMiB() const {
  return spin_->value();
}

BudgetPanel::Driver BudgetPanel::driverFor(const QString& method) const {
  Driver d;
  const mfr::MethodInfo* info = ctx_.methodInfo(method);
  if (!info) {
    if (isOnDemandCpuMethod(ctx_, method)) {  // (with a MethodInfo it is read like any other)
      d.knob = Knob::Budget;
      d.param = "budget_mib";
    }
    return d;
  }
  const auto find = [&](const std::string& name) -> const mfr::ParamSpec* {
    for (const mfr::ParamSpec& s : info->params)
      if (s.name == name) return &s;
    return nullptr;
  };
  if (find("budget_mib")) {
    d.knob = Knob::Budget;
    d.param = "budget_mib";
  } else if (find("pool_mib") && find("pool")) {
    d.knob = Knob::Pool;
    d.param = "pool_mib";
  } else {
    for (const char* name : {"k", "slots"})
      if (const mfr::ParamSpec* s = find(name); s && s->type == mfr::ParamSpec::Type::Int) {
        d.knob = Knob::Slots;
        d.param = name;
        d.minValue = std::max<long long>(1, static_cast<long long>(s->min));
        d.maxValue = static_cast<long long>(s->max);
        break;
      }
  }
  return d;
}

void BudgetPanel::setBudget(int mib) {
  {
    const QSignalBlocker a(slider_), b(spin_);
    slider_->setValue(mib);
    spin_->setValue(mib);
  }
  driving_ = true;
  corrections_ = 0;
  showKnob();
  applyBudget();
}

void BudgetPanel::methodChanged() {
  const Driver d = driverFor(ctx_.method());
  {
    const QSignalBlocker block(methodCombo_);
    methodCombo_->setCurrentIndex(methodCombo_->findData(ctx_.method()));
  }
  showKnob();
  corrections_ = 0;
  showRobustness();
  showFrame();
  if (driving_) applyBudget();
}

void BudgetPanel::showKnob() {
  const Driver d = driverFor(ctx_.method());
  QString text;
  switch (d.knob) {
    case Knob::None:
      text = tr("nothing: %1 has no memory parameter").arg(ctx_.method());
      break;
    case Knob::Budget:
      text = tr("budget_mib — the method picks k per frame within the budget");
      break;
    case Knob::Pool:
      text = tr("pool = fixed, pool_mib = budget − per-pixel heads");
      break;
    case Knob::Slots:
      text = tr("%1 — the largest that fits (%2 … %3)")
                 .arg(QString::fromStdString(d.param))
                 .arg(d.minValue)
                 .arg(d.maxValue);
      break;
  }
  // Until the budget is moved (or a session says so) the method keeps its own parameters and the
  // bar below is only a reference line.
  if (d.knob != Knob::None && !driving_) text += tr("; not applied until you set a budget");
  knobLabel_->setText(text);
}

void BudgetPanel::showRobustness() {
  const mfr::ParamSpec* spec = findParam(ctx_, ctx_.method(), "robustness");
  robustnessRow_->setVisible(spec != nullptr);
  robustnessLabel_->setVisible(spec != nullptr);
  if (!spec) return;
  const QSignalBlocker a(robustness_), b(robustnessSlider_);
  robustness_->setRange(spec->min, spec->max);
  const double value = QString::fromStdString(parameterValue(ctx_, "robustness")).toDouble();
  robustness_->setValue(value);
  const double span = std::max(spec->max - spec->min, 1e-9);
  robustnessSlider_->setValue(static_cast<int>(std::lround((value - spec->min) / span * kRobustnessSteps)));
}

// What the number is, then why it is missing: the reason alone replaced the description, which
// then stayed empty from the first measured frame on (a bug hunt).
QString BudgetPanel::qualityToolTip(const QLabel* label, const QString& reason) const {
  const QString what = label == rmseLabel_
                           ? tr("Root-mean-square RGB error against the exact image (oracle), 0 … 1")
                           : tr("Mean (max) LDR-FLIP error against the exact image: 0 identical … 1 most different");
  return reason.isEmpty() ? what : what + QLatin1Char('\n') + reason;
}

void BudgetPanel::showQuality() {
  if (!ctx_.frameError().isEmpty()) {  // no frame on screen to measure
    for (QLabel* label : {rmseLabel_, flipLabel_}) {
      label->setText(tr("—"));
      label->setToolTip(qualityToolTip(label, ctx_.frameError()));
    }
    return;
  }
  const FrameQuality q = ctx_.frameQuality();
  rmseLabel_->setToolTip(qualityToolTip(rmseLabel_, q.error));
  flipLabel_->setToolTip(qualityToolTip(flipLabel_, q.error));
  if (!q.valid) {
    // Not computed for this frame: say why (the exact image may not fit in memory), not
    // "computing…" for ever.
    rmseLabel_->setText(q.error.isEmpty() ? tr("computing…") : tr("not computed"));
    flipLabel_->setText(q.error.isEmpty() ? tr("computing…") : q.error);
    return;
  }
  rmseLabel_->setText(QString::number(q.rmse, 'f', 5));
  flipLabel_->setText(tr("%1 (max %2)").arg(q.flipMean, 0, 'f', 4).arg(q.flipMax, 0, 'f', 3));
}

// Bytes per slot from the lowest and highest measured values (bytes are linear in the value at
// one size), or `fallback` with fewer than two.
namespace {
double bytesPerSlot(const std::map<long long, std::uint64_t>& bytes, double fallback) {
  if (bytes.size() < 2) return fallback;
  const auto lo = bytes.begin();
  const auto hi = std::prev(bytes.end());
  return static_cast<double>(hi->second - lo->second) / static_cast<double>(hi->first - lo->first);
}
}  // namespace

BudgetPanel::Model BudgetPanel::modelAt(double pixels) const {
  // Measured at the view's size; per-pixel storage scales with the pixels.
  const double viewPixels = std::max(1.0, static_cast<double>(ctx_.imageSize().width()) * ctx_.imageSize().height());
  const double scale = pixels / viewPixels;
  Model m;
  // Before the first measurement assume 8 bytes per pixel besides the pool (head pointer,
  // counter); the first frame measures the real overhead.
  m.poolOverhead = fit_.poolOverhead >= 0 ? fit_.poolOverhead * scale : 8.0 * pixels;
  m.perSlot = bytesPerSlot(fit_.bytes, 8.0 * viewPixels);  // RGBA8 + depth per slot until measured
  if (!fit_.bytes.empty()) {
    m.fixed =
        static_cast<double>(fit_.bytes.begin()->second) - m.perSlot * static_cast<double>(fit_.bytes.begin()->first);
  }
  m.perSlot *= scale;
  m.fixed *= scale;
  return m;
}

std::map<std::string, std::string> BudgetPanel::paramsFor(const Driver& d, const Model& m) const {
  const double budget = budgetMiB() * kMiB;
  switch (d.knob) {
    case Knob::None:
      return {};
    case Knob::Budget:
      return {{"budget_mib", std::to_string(budgetMiB())}};
    case Knob::Pool: {
      // The method rounds the pool to whole nodes, so keep a small margin below the budget, and
      // round the MiB text down, never up.
      const double pool = std::max(budget - m.poolOverhead - kPoolMarginBytes, kMiB / 64);
      const double poolMiB = std::floor(pool / kMiB * 1e6) / 1e6;
      return {{"pool", "fixed"}, {"pool_mib", QString::number(poolMiB, 'f', 6).toStdString()}};
    }
    case Knob::Slots: {
      const auto k = static_cast<long long>(std::floor((budget - m.fixed) / std::max(m.perSlot, 1.0)));
      return {{d.param, std::to_string(std::clamp(k, d.minValue, d.maxValue))}};
    }
  }
  return {};
}

void BudgetPanel::applyBudget() {
  const Driver d = driverFor(ctx_.method());
  if (d.knob == Knob::None) return;
  ctx_.setParams(paramsFor(d, modelAt(static_cast<double>(ctx_.imageSize().width()) * ctx_.imageSize().height())));
}

std::map<std::string, std::string> BudgetPanel::exportParams(QSize size,
                                                             const std::map<std::string, std::string>* tried,
                                                             const mfr::Stats* measured) const {
  const Driver d = driverFor(ctx_.method());
  // The budget's own parameter (budget_mib) holds at any size; at the view's size the view's
  // fitted parameters hold once a frame of this method there measured them within the budget (a
  // view that has drawn nothing, as under mfrview --screenshot, has only a first guess).
  const mfr::Stats& shown = ctx_.stats();
  const bool viewFitted = size == ctx_.imageSize() && QString::fromStdString(shown.method) == ctx_.method() &&
                          static_cast<double>(shown.bytesAllocated) <= budgetMiB() * kMiB;
  if (!driving_ || (d.knob != Knob::Pool && d.knob != Knob::Slots) || (viewFitted && !tried)) return {};
  Model m = modelAt(static_cast<double>(size.width()) * size.height());
  if (!tried || !measured) {
    exportTries_.clear();
    return paramsFor(d, m);
  }
  const auto given = tried->find(d.knob == Knob::Pool ? std::string("pool_mib") : d.param);
  if (given == tried->end()) return paramsFor(d, m);
  // The last render at this size measured the bytes besides what the parameter buys. A render
  // that fits is kept (the same parameters end the tries) unless a larger value fits too.
  const double budget = budgetMiB() * kMiB;
  const double bytes = static_cast<double>(measured->bytesAllocated);
  // Over the budget with the least the parameter can be: no picture (the export wrote one at
  // 5.5 times the budget: a bug hunt), as the budget_mib methods refuse a budget below k = 1.
  const auto refuse = [&] {
    throw mfr::Error(QStringLiteral("budget %1 MiB").arg(budgetMiB()).toStdString(),
                     QStringLiteral("below what %1 needs at %2x%3 with %4=%5 (%6 MiB = %7 bytes)")
                         .arg(ctx_.method())
                         .arg(size.width())
                         .arg(size.height())
                         .arg(QString::fromStdString(given->first), QString::fromStdString(given->second))
                         .arg(bytes / kMiB, 0, 'f', 3)
                         .arg(measured->bytesAllocated)
                         .toStdString());
  };
  if (d.knob == Knob::Pool) {
    // The method rounds the pool to whole nodes: refitting a pool that fits crept by a node a try.
    if (bytes <= budget) return *tried;
    m.poolOverhead = bytes - std::stod(given->second) * kMiB;
    std::map<std::string, std::string> next = paramsFor(d, m);
    if (next == *tried) refuse();
    return next;
  }
  // Slots: at one size the bytes are linear in the value, so two measured renders give the exact
  // bytes per slot (the view's model may still be its first guess, 8 bytes per pixel and slot:
  // kpeel's 16 made the tries swing over and under the budget; a review).
  const long long value = std::stoll(given->second);
  exportTries_[value] = measured->bytesAllocated;
  m.perSlot = bytesPerSlot(exportTries_, m.perSlot);
  m.fixed = bytes - m.perSlot * static_cast<double>(value);
  std::map<std::string, std::string> next = paramsFor(d, m);
  if (bytes <= budget && std::stoll(next[d.param]) <= value) return *tried;
  if (bytes > budget && value <= d.minValue) refuse();
  return next;
}

void BudgetPanel::frameRendered() {
  const mfr::Stats& s = ctx_.stats();
  if (QString::fromStdString(s.method) != ctx_.method()) return;
  const QSize size = ctx_.imageSize();
  const std::string key = s.method + "@" + std::to_string(size.width()) + "x" + std::to_string(size.height());
  if (key != fit_.key) fit_ = Fit{key, {}, -1};
  const Driver d = driverFor(ctx_.method());
  bool refit = false;
  if (d.knob == Knob::Slots) {
    const long long value = std::stoll(parameterValue(ctx_, d.param));
    refit = !fit_.bytes.contains(value);
    fit_.bytes[value] = s.bytesAllocated;
  } else if (d.knob == Knob::Pool && parameterValue(ctx_, "pool") == "fixed") {
    const double overhead = static_cast<double>(s.bytesAllocated) - std::stod(parameterValue(ctx_, "pool_mib")) * kMiB;
    refit = std::abs(overhead - fit_.poolOverhead) > 1.0;
    fit_.poolOverhead = overhead;
  }
  showFrame();
  showQuality();
  qualityTimer_->start();
  // A better model (or an over-budget frame) changes the parameter: re-render, a few times at
  // most per budget change. Deferred: this runs inside the view's paint.
  if (driving_ && refit && corrections_ < kMaxCorrections) {
    ++corrections_;
    QTimer::singleShot(0, this, &BudgetPanel::applyBudget);
  }
}

void BudgetPanel::showFrame() {
  const mfr::Stats& s = ctx_.stats();
  const QLocale locale;
  const double budget = budgetMiB() * kMiB;
  // The last frame is another method's (the new one's has not come, or cannot be drawn): its
  // numbers read as this method's (fkb "fitting" at kplus-dynamic's 9.46 MiB: a bug hunt). Or the
  // current settings drew none (a budget below the least setting): the last frame's numbers are
  // not on screen, and read beside the new budget ("15.3 of 16 MiB" at 1 MiB: a bug hunt).
  const QString error = ctx_.frameError();
  memoryBar_->setToolTip(error);
  if (QString::fromStdString(s.method) != ctx_.method() || !error.isEmpty()) {
    memoryBar_->setValue(0);
    memoryBar_->setFormat(tr("no frame of %1").arg(ctx_.method()));  // the reason in its tooltip
    memoryBar_->setStyleSheet(QString());
    for (QLabel* label : {memoryLabel_, capturedLabel_, kLabel_, exactLabel_}) label->setText(tr("—"));
    histogram_->setMarker(0, false);
    return;
  }
  const double allocated = static_cast<double>(s.bytesAllocated);
  memoryBar_->setValue(static_cast<int>(std::min(1000.0, 1000.0 * allocated / budget)));
  memoryBar_->setFormat(
      tr("%1 of %2 MiB (%3 %)").arg(mib(allocated)).arg(budgetMiB()).arg(100.0 * allocated / budget, 0, 'f', 0));
  // Red only when the budget is in force: before the slider is used it is a reference line.
  memoryBar_->setStyleSheet(
      driving_ && allocated > budget ? QStringLiteral("QProgressBar::chunk { background: #d04030; }") : QString());
  memoryLabel_->setText(tr("%1 MiB of %2 MiB allocated").arg(mib(static_cast<double>(s.bytesUsed)), mib(allocated)));
  // Blending methods (wboit, mboit) keep no fragment but use every one: not "0 % captured".
  const bool blendsAll = s.kMax == 0 && s.fragmentsStored == 0 && s.fragmentsDropped == 0;
  capturedLabel_->setText(
      blendsAll && s.fragmentsGenerated
          ? tr("all %1 fragments blended, none stored").arg(locale.toString(s.fragmentsGenerated))
      : s.fragmentsGenerated
          ? tr("%1 % (%2 of %3 fragments)")
                .arg(100.0 * static_cast<double>(s.fragmentsStored) / static_cast<double>(s.fragmentsGenerated), 0, 'f',
                     1)
                .arg(locale.toString(s.fragmentsStored), locale.toString(s.fragmentsGenerated))
          : tr("—"));
  kLabel_->setText(s.kMax == 0        ? tr("— (no per-pixel capacity)")
                   : s.kMin == s.kMax ? QString::number(s.kMax)
                                      : QStringLiteral("%1 … %2").arg(s.kMin).arg(s.kMax));
  const std::string* exactAt = s.note("exact at");
  exactLabel_->setText(exactAt ? QString::fromStdString(*exactAt).replace(QStringLiteral(">= "), QStringLiteral("≥ "))
                               : tr("—"));
  histogram_->setMarker(driverFor(ctx_.method()).knob == Knob::Pool ? 0 : static_cast<int>(s.kMax), s.kMin != s.kMax);
}

QJsonObject BudgetPanel::saveSettings() const {
  return {{"budget_mib", budgetMiB()}, {"driving", driving_}};
}

void BudgetPanel::loadSettings(const QJsonObject& settings) {
  // A number that is not a whole MiB in the spin box's range was the default, or clamped, silently.
  const double given = settings.value("budget_mib").toDouble(kDefaultBudgetMiB);
  const int mib = static_cast<int>(std::lround(std::clamp(given, double(spin_->minimum()), double(spin_->maximum()))));
  if (given != mib)
    ctx_.note(tr("budget: budget_mib %1 is not a whole number of MiB in %2 … %3: %4 is used")
                  .arg(given)
                  .arg(spin_->minimum())
                  .arg(spin_->maximum())
                  .arg(mib));
  const QSignalBlocker a(slider_), b(spin_);
  slider_->setValue(mib);
  spin_->setValue(mib);
  driving_ = settings.value("driving").toBool(false);
  showKnob();
  corrections_ = 0;
  if (driving_) applyBudget();  // same parameters as saved for the same image size
}
