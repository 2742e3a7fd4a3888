#include "clip_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QGridLayout>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
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
        // Keep min ≤ max: the other face gives way, moved here without a signal of its own (its
        // own apply would show the model's old face back on this slider before it was applied).
        QSlider* other = s == low_[a] ? high_[a] : low_[a];
        const bool pushed = s == low_[a] ? other->value() < s->value() : other->value() > s->value();
        if (pushed) {
          const QSignalBlocker block(other);
          other->setValue(s->value());
        }
        applyBox(a, pushed ? Face::Both : s == low_[a] ? Face::Low : Face::High);
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

  sectionEnabled_ = new QCheckBox(tr("Section plane"), this);
  sectionEnabled_->setObjectName(QStringLiteral("sectionEnabled"));
  sectionEnabled_->setToolTip(
      tr("Cut the scene with a plane: what lies on the far side is removed, closed parts are capped"));
  layout->addWidget(sectionEnabled_);
  auto* section = new QGridLayout;
  sectionAxis_ = new QComboBox(this);
  sectionAxis_->setObjectName(QStringLiteral("sectionAxis"));
  sectionAxis_->addItems({QStringLiteral("X"), QStringLiteral("Y"), QStringLiteral("Z")});
  sectionFlip_ = new QCheckBox(tr("Flip"), this);
  sectionFlip_->setObjectName(QStringLiteral("sectionFlip"));
  sectionFlip_->setToolTip(tr("Keep the other side of the plane"));
  sectionCaps_ = new QCheckBox(tr("Caps"), this);
  sectionCaps_->setObjectName(QStringLiteral("sectionCaps"));
  sectionCaps_->setToolTip(tr("Close every cut closed part with its cross-section"));
  sectionCaps_->setChecked(true);
  sectionSlice_ = new QCheckBox(tr("Volume slice"), this);
  sectionSlice_->setObjectName(QStringLiteral("sectionSlice"));
  sectionSlice_->setToolTip(
      tr("Show each volume's samples on the plane, grayscale over its transfer function's range (a CT's slice)"));
  sectionOffset_ = new QSlider(Qt::Horizontal, this);
  sectionOffset_->setObjectName(QStringLiteral("sectionOffset"));
  sectionOffset_->setRange(0, kSteps);
  sectionOffset_->setValue(kSteps / 2);
  sectionValue_ = new QLabel(this);
  sectionValue_->setObjectName(QStringLiteral("sectionValue"));
  // Narrow, like the box's rows: the dock shares the left side with the scene tree.
  section->addWidget(sectionAxis_, 0, 0);
  section->addWidget(sectionFlip_, 0, 1);
  section->addWidget(sectionCaps_, 0, 2);
  section->addWidget(sectionOffset_, 1, 0, 1, 2);
  section->addWidget(sectionValue_, 1, 2);
  sectionAlign_ = new QPushButton(tr("Align to view"), this);
  sectionAlign_->setObjectName(QStringLiteral("sectionAlign"));
  sectionAlign_->setToolTip(
      tr("The plane through the view's target, facing away from the eye: the near half is cut away"));
  section->addWidget(sectionSlice_, 2, 0);
  section->addWidget(sectionAlign_, 2, 1, 1, 2, Qt::AlignRight);
  sectionReport_ = new QLabel(this);
  sectionReport_->setObjectName(QStringLiteral("sectionReport"));
  sectionReport_->setWordWrap(true);
  section->addWidget(sectionReport_, 3, 0, 1, 3);
  section->setColumnStretch(0, 1);
  layout->addLayout(section);
  layout->addStretch(1);
  // Each control changes only what it shows: a flag or the side keeps the plane where it is (a
  // file's plane need not sit on a slider step), the offset and the axis move it.
  connect(sectionEnabled_, &QCheckBox::toggled, this, [this] { placeSection(); });
  connect(sectionAxis_, &QComboBox::currentIndexChanged, this, [this] { placeSection(); });
  connect(sectionOffset_, &QSlider::valueChanged, this, [this] { placeSection(); });
  // The other side: the normal turned round (the box follows the model: flipped is a normal
  // against its axis).
  connect(sectionFlip_, &QCheckBox::toggled, this,
          [this] { editSection([](mfr::SectionPlane& plane) { plane.normal = -plane.normal; }); });
  connect(sectionCaps_, &QCheckBox::toggled, this,
          [this](bool on) { editSection([on](mfr::SectionPlane& plane) { plane.caps = on; }); });
  connect(sectionSlice_, &QCheckBox::toggled, this,
          [this](bool on) { editSection([on](mfr::SectionPlane& plane) { plane.slice = on; }); });
  connect(sectionAlign_, &QPushButton::clicked, this, [this] {
    const mfr::Camera& camera = model_.camera();
    model_.setSection(
        mfr::SectionPlane{camera.target, camera.forward(), sectionCaps_->isChecked(), sectionSlice_->isChecked()});
    showModel();
  });

  connect(enabled_, &QCheckBox::toggled, this, [this] { applyBox(-1, Face::Both); });
  connect(reset_, &QPushButton::clicked, this, [this] {
    showing_ = true;
    for (int a = 0; a < 3; ++a) {
      low_[a]->setValue(0);
      high_[a]->setValue(kSteps);
    }
    showing_ = false;
    applyBox(-1, Face::Both);
  });
  connect(&model_, &ViewerModel::sceneChanged, this, &ClipPanel::showModel);
  showModel();  // an unchanged model emits nothing: the controls still follow the switches
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

namespace {

// The bounds' extent along unit n: the lowest and highest dot(n, corner).
std::pair<double, double> extentAlong(const mfr::Bounds& b, const glm::dvec3& n) {
  double lo = 1e300, hi = -1e300;
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 corner = b.corner(c);
    lo = std::min(lo, glm::dot(n, corner));
    hi = std::max(hi, glm::dot(n, corner));
  }
  return {lo, hi};
}

}  // namespace

mfr::SectionPlane ClipPanel::sectionFromPosition(const mfr::Bounds& bounds, const glm::dvec3& axis, int position,
                                                 bool flip, bool caps, bool slice) {
  const auto [lo, hi] = extentAlong(bounds, axis);
  mfr::SectionPlane plane;
  plane.point = axis * (lo + (hi - lo) * position / kSteps);
  plane.normal = flip ? -axis : axis;
  plane.caps = caps;
  plane.slice = slice;
  return plane;
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

  // The section: which axis (or the file's own normal), which side, where along it.
  const std::optional<mfr::SectionPlane>& section = model_.section();
  sectionEnabled_->setEnabled(usable);
  sectionAlign_->setEnabled(usable);
  sectionEnabled_->setChecked(section.has_value());
  if (section) {
    const glm::dvec3 n = glm::normalize(section->normal);
    int axis = -1;
    for (int a = 0; a < 3; ++a)
      if (std::abs(std::abs(n[a]) - 1.0) < 1e-12) axis = a;
    glm::dvec3 base = n;
    bool flip = false;
    if (axis >= 0) {
      flip = n[axis] < 0.0;
      base = glm::dvec3(0.0);
      base[axis] = 1.0;
      if (sectionAxis_->count() > 3) sectionAxis_->removeItem(3);
      sectionAxis_->setCurrentIndex(axis);
    } else {
      // A plane of its own normal: Custom is that normal (kept when the plane is only flipped, so
      // Flip shows which way round it is).
      if (std::abs(std::abs(glm::dot(n, customNormal_)) - 1.0) > 1e-12) customNormal_ = n;
      flip = glm::dot(n, customNormal_) < 0.0;
      base = customNormal_;
      if (sectionAxis_->count() == 3) sectionAxis_->addItem(tr("Custom"));
      sectionAxis_->setCurrentIndex(3);
    }
    sectionFlip_->setChecked(flip);
    sectionCaps_->setChecked(section->caps);
    sectionSlice_->setChecked(section->slice);
    const auto [lo, hi] = extentAlong(bounds, base);
    const double at = glm::dot(base, section->point);
    sectionOffset_->setValue(
        hi > lo ? std::clamp(static_cast<int>(std::lround((at - lo) / (hi - lo) * kSteps)), 0, kSteps) : kSteps / 2);
    sectionValue_->setText(QStringLiteral("%1").arg(at, 0, 'g', 5));
    // The cut the renderers draw (made once per edit by the model).
    if (!model_.sectionError().isEmpty()) {
      sectionReport_->setText(model_.sectionError());
      sectionReport_->setToolTip({});
    } else {
      const mfr::SectionReport& report = model_.sectionReport();
      QString text = (report.cut == 1 ? tr("1 part cut") : tr("%1 parts cut").arg(report.cut));
      QString names;
      if (section->caps) {
        text += tr(", %1 capped").arg(report.capped);
        // The caps' area: the cut solids' cross-section (mfr info --section per part).
        if (report.totalCapArea() > 0.0) text += tr(", cross-section %1").arg(report.totalCapArea(), 0, 'g', 6);
        if (!report.open.empty()) {
          text += tr("; %1 open along the cut, without a cap").arg(report.open.size());
          for (const std::string& name : report.open) names += QString::fromStdString(name) + QLatin1Char('\n');
        }
      }
      if (section->slice)
        text += report.slices == 0   ? tr("; the plane misses the volume")
                : report.slices == 1 ? tr("; 1 volume slice")
                                     : tr("; %1 volume slices").arg(report.slices);
      sectionReport_->setText(text);
      sectionReport_->setToolTip(names.trimmed());
    }
  } else {
    sectionValue_->setText(QStringLiteral("—"));
    sectionReport_->clear();
    sectionReport_->setToolTip({});
  }
  for (QWidget* w : std::initializer_list<QWidget*>{sectionAxis_, sectionFlip_, sectionCaps_, sectionOffset_})
    w->setEnabled(usable && section.has_value());
  sectionSlice_->setEnabled(usable && section.has_value() && !model_.scene().volumes.empty());
  showing_ = false;
}

void ClipPanel::applyBox(int axis, Face face) {
  if (showing_) return;
  if (!enabled_->isChecked()) {
    model_.setClipBox(std::nullopt);
  } else {
    std::array<int, 3> low{}, high{};
    for (int a = 0; a < 3; ++a) {
      low[static_cast<std::size_t>(a)] = low_[a]->value();
      high[static_cast<std::size_t>(a)] = high_[a]->value();
    }
    mfr::Bounds box = boxFromPositions(model_.scene().bounds(), low, high);
    // One axis's face (or both, one pushing the other) moved: every other face keeps the model's
    // value (a file's box need not sit on slider steps, and may reach past the bounds).
    if (const std::optional<mfr::Bounds>& current = model_.clipBox(); current && axis >= 0) {
      const mfr::Bounds moved = box;
      box = *current;
      if (face != Face::High) box.min[axis] = moved.min[axis];
      if (face != Face::Low) box.max[axis] = moved.max[axis];
    }
    model_.setClipBox(box);
  }
  showModel();  // an unchanged model emits nothing: the controls still follow the switches
}

void ClipPanel::placeSection() {
  if (showing_) return;
  if (!sectionEnabled_->isChecked()) {
    model_.setSection(std::nullopt);
  } else {
    const int index = sectionAxis_->currentIndex();
    glm::dvec3 axis = customNormal_;
    if (index >= 0 && index < 3) {
      axis = glm::dvec3(0.0);
      axis[index] = 1.0;
    }
    model_.setSection(sectionFromPosition(model_.scene().bounds(), axis, sectionOffset_->value(),
                                          sectionFlip_->isChecked(), sectionCaps_->isChecked(),
                                          sectionSlice_->isChecked()));
  }
  showModel();
}

void ClipPanel::editSection(const std::function<void(mfr::SectionPlane&)>& edit) {
  if (showing_) return;
  if (std::optional<mfr::SectionPlane> plane = model_.section()) {
    edit(*plane);
    model_.setSection(*plane);
  }
  showModel();
}
