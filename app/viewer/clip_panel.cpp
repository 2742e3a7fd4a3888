#include "clip_panel.hpp"

#include <QCheckBox>
#include <QGridLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

#include "viewer_model.hpp"

ClipPanel::ClipPanel(ViewerModel& model, QWidget* parent) : QWidget(parent), model_(model) {
  auto* layout = new QVBoxLayout(this);
  enabled_ = new QCheckBox(tr("Clip to a box"), this);
  enabled_->setObjectName(QStringLiteral("clipEnabled"));
  enabled_->setToolTip(tr("Draw only what lies inside the box: surfaces are cut open, the volume is cropped"));
  layout->addWidget(enabled_);
  auto* grid = new QGridLayout;
  const char* axes[3] = {"X", "Y", "Z"};
  for (int a = 0; a < 3; ++a) {
    const auto slider = [&](const QString& name, int value) {
      auto* s = new QSlider(Qt::Horizontal, this);
      s->setObjectName(name);
      s->setRange(0, kSteps);
      s->setValue(value);
      connect(s, &QSlider::valueChanged, this, [this, s, a](int) {
        // Keep min ≤ max: the other face gives way.
        if (s == low_[a] && high_[a]->value() < s->value()) high_[a]->setValue(s->value());
        if (s == high_[a] && low_[a]->value() > s->value()) low_[a]->setValue(s->value());
        apply();
      });
      return s;
    };
    low_[a] = slider(QStringLiteral("clipMin%1").arg(axes[a]), 0);
    high_[a] = slider(QStringLiteral("clipMax%1").arg(axes[a]), kSteps);
    values_[a] = new QLabel(this);
    values_[a]->setObjectName(QStringLiteral("clipValues%1").arg(axes[a]));
    grid->addWidget(new QLabel(QString::fromLatin1(axes[a]), this), 2 * a, 0, 2, 1);
    grid->addWidget(low_[a], 2 * a, 1);
    grid->addWidget(high_[a], 2 * a + 1, 1);
    grid->addWidget(values_[a], 2 * a, 2, 2, 1);
  }
  grid->setColumnStretch(1, 1);
  layout->addLayout(grid);
  reset_ = new QPushButton(tr("Reset"), this);
  reset_->setObjectName(QStringLiteral("clipReset"));
  layout->addWidget(reset_, 0, Qt::AlignRight);
  layout->addStretch(1);

  connect(enabled_, &QCheckBox::toggled, this, [this] { apply(); });
  connect(reset_, &QPushButton::clicked, this, [this] {
    showing_ = true;
    for (int a = 0; a < 3; ++a) {
      low_[a]->setValue(0);
      high_[a]->setValue(kSteps);
    }
    showing_ = false;
    apply();
  });
  connect(&model_, &ViewerModel::sceneChanged, this, &ClipPanel::showModel);
  showModel();
}

mfr::Bounds ClipPanel::boxFromPositions(const mfr::Bounds& bounds, const std::array<int, 3>& low,
                                        const std::array<int, 3>& high) {
  mfr::Bounds box;
  for (int a = 0; a < 3; ++a) {
    const double extent = bounds.max[a] - bounds.min[a];
    box.min[a] = bounds.min[a] + extent * low[static_cast<std::size_t>(a)] / kSteps;
    box.max[a] = bounds.min[a] + extent * high[static_cast<std::size_t>(a)] / kSteps;
  }
  return box;
}

void ClipPanel::showModel() {
  if (showing_) return;
  showing_ = true;
  const std::optional<mfr::Bounds>& clip = model_.clipBox();
  const mfr::Bounds bounds = model_.scene().bounds();
  const bool usable = model_.hasScene() && bounds.valid();
  enabled_->setEnabled(usable);
  enabled_->setChecked(clip.has_value());
  for (int a = 0; a < 3; ++a) {
    const double extent = bounds.max[a] - bounds.min[a];
    // The box's faces as slider positions (a file's box may reach past the bounds: clamped).
    const auto position = [&](double v, int fallback) {
      if (!clip || !(extent > 0.0)) return fallback;
      return std::clamp(static_cast<int>(std::lround((v - bounds.min[a]) / extent * kSteps)), 0, kSteps);
    };
    low_[a]->setValue(position(clip ? clip->min[a] : 0.0, 0));
    high_[a]->setValue(position(clip ? clip->max[a] : 0.0, kSteps));
    low_[a]->setEnabled(usable && clip.has_value());
    high_[a]->setEnabled(usable && clip.has_value());
    values_[a]->setText(clip ? QStringLiteral("%1 … %2").arg(clip->min[a], 0, 'g', 5).arg(clip->max[a], 0, 'g', 5)
                             : QStringLiteral("—"));
  }
  reset_->setEnabled(usable && clip.has_value());
  showing_ = false;
}

void ClipPanel::apply() {
  if (showing_) return;
  if (!enabled_->isChecked()) {
    model_.setClipBox(std::nullopt);
    showModel();  // an unchanged model emits nothing: the controls still follow the switch
    return;
  }
  std::array<int, 3> low{}, high{};
  for (int a = 0; a < 3; ++a) {
    low[static_cast<std::size_t>(a)] = low_[a]->value();
    high[static_cast<std::size_t>(a)] = high_[a]->value();
  }
  model_.setClipBox(boxFromPositions(model_.scene().bounds(), low, high));
  showModel();
}
