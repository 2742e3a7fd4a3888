#include "probe_panel.hpp"

#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QTableWidget>
#include <QTimer>
#include <QVBoxLayout>

#include <algorithm>
#include <vector>
#include <cmath>
#include <exception>

#include "header_sizing.hpp"
#include "render_view.hpp"
#include "viewer_model.hpp"

namespace {

QColor rgbOf(std::uint32_t packed) {
  return QColor(static_cast<int>(packed & 0xffu), static_cast<int>((packed >> 8) & 0xffu),
                static_cast<int>((packed >> 16) & 0xffu));
}

QTableWidgetItem* item(const QString& text, Qt::Alignment align = Qt::AlignLeft | Qt::AlignVCenter) {
  auto* i = new QTableWidgetItem(text);
  i->setTextAlignment(align);
  i->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable);
  return i;
}

}  // namespace

ProbePanel::ProbePanel(ViewerModel& model, RenderView& view, QWidget* parent)
    : QWidget(parent), model_(model), view_(view) {
  auto* layout = new QVBoxLayout(this);
  summary_ = new QLabel(tr("Ctrl + click the view to list what lies behind a pixel."), this);
  summary_->setObjectName(QStringLiteral("probeSummary"));
  summary_->setWordWrap(true);
  summary_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(summary_);
  table_ = new QTableWidget(0, ColumnCount, this);
  table_->setObjectName(QStringLiteral("probeTable"));
  table_->setHorizontalHeaderLabels({tr("#"), tr("Eye depth"), tr("Part"), tr("Colour"), tr("α"), tr("Faces"),
                                     tr("Share"), tr("Held"), tr("Hybrid"), tr("Volume"), tr("Z-thickness"),
                                     tr("Field value")});
  table_->horizontalHeaderItem(Share)->setToolTip(
      tr("The fragment's share of the pixel's colour: α·Π(1 − α) of the fragments in front of it"));
  table_->horizontalHeaderItem(Held)->setToolTip(
      tr("Whether the pane's method holds this fragment (with the operation hybrid: in its core, or left to the "
         "tail)"));
  table_->horizontalHeaderItem(HybridShare)
      ->setToolTip(tr("With the operation hybrid (the budget methods): the fragment's share of the colour the method "
                      "draws — the core composited exactly, the tail by its weighted average"));
  table_->setColumnHidden(HybridShare, true);
  table_->horizontalHeaderItem(VolumeShare)
      ->setToolTip(tr("With the operation volume: the surface's share of the pixel's colour through the medium in "
                      "front of it (the summary gives the medium's share)"));
  table_->setColumnHidden(VolumeShare, true);
  table_->horizontalHeaderItem(ZThicknessShare)
      ->setToolTip(tr("With the operation zthickness: the surface's share of the blended colour (surfaces closer "
                      "than the thickness blend instead of covering each other)"));
  table_->setColumnHidden(ZThicknessShare, true);
  table_->horizontalHeaderItem(FieldValue)
      ->setToolTip(tr("For a part coloured by a field (Colour by): the field's value where the pixel's ray meets it"));
  table_->setColumnHidden(FieldValue, true);
  table_->verticalHeader()->hide();
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  table_->horizontalHeader()->setSectionResizeMode(Part, QHeaderView::Stretch);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  layout->addWidget(table_, 1);
  clear_ = new QPushButton(tr("Clear"), this);
  clear_->setObjectName(QStringLiteral("probeClear"));
  clear_->setEnabled(false);
  layout->addWidget(clear_, 0, Qt::AlignRight);
  connect(clear_, &QPushButton::clicked, this, &ProbePanel::clear);

  connect(&view_, &RenderView::probeRequested, this, &ProbePanel::probe);
  connect(table_, &QTableWidget::cellDoubleClicked, this, [this](int row) {
    const QTableWidgetItem* part = table_->item(row, Part);
    if (part && part->data(Qt::UserRole).toInt() >= 0) emit partChosen(part->data(Qt::UserRole).toInt());
  });
  // Full frames only (navigation previews are not reported): the probe follows the view without
  // costing every drag step a ray cast.
  connect(&model_, &ViewerModel::frameRendered, this, [this] {
    if (point_) QTimer::singleShot(0, this, &ProbePanel::refreshIfChanged);
  });
  connect(&model_, &ViewerModel::sceneLoaded, this, &ProbePanel::clear);
  // Parts added or removed (isosurfaces): the rows' part indices may name other parts until the
  // next frame probes again, so they choose none meanwhile (a review).
  connect(&model_, &ViewerModel::partsChanged, this, [this] {
    for (int row = 0; row < table_->rowCount(); ++row)
      if (QTableWidgetItem* part = table_->item(row, Part)) part->setData(Qt::UserRole, -1);
  });
  // A frame that cannot be drawn (every part hidden) reports no frame: the probe says why instead
  // of listing the fragments of what was drawn before (a bug hunt).
  connect(&model_, &ViewerModel::renderErrorChanged, this, [this] {
    if (point_ && model_.mainPaneFailed()) QTimer::singleShot(0, this, &ProbePanel::refresh);
  });
}

void ProbePanel::probe(QPointF point) {
  point_ = point;
  clear_->setEnabled(true);
  // The mark moves only here and in clear(): moving a child of the view exposes the view, which
  // renders a frame, and a frame must not lead to another one.
  view_.setProbeMark(point_);
  refresh();
}

void ProbePanel::refreshIfChanged() {
  if (point_ && !(model_.frameKey(probedSide_) == probedKey_)) refresh();
}

void ProbePanel::clear() {
  point_.reset();
  view_.setProbeMark(std::nullopt);
  table_->setRowCount(0);
  summary_->setText(tr("Ctrl + click the view to list what lies behind a pixel."));
  clear_->setEnabled(false);
}

void ProbePanel::refresh() {
  if (!point_) return;
  try {
    const ViewProbe result = view_.probeAt(*point_);
    probedSide_ = result.side;
    show(result);
  } catch (const std::exception& e) {
    probedSide_ = 0;
    table_->setRowCount(0);
    summary_->setText(tr("Probe: %1").arg(QString::fromUtf8(e.what())));
  }
  probedKey_ = model_.frameKey(probedSide_);
  emit probed();
}

void ProbePanel::show(const ViewProbe& r) {
  const mfr::PixelProbe& p = r.probe;
  const auto n = static_cast<int>(p.fragments.size());
  QString text = tr("Pixel (%1, %2) of %3×%4%5: %n fragment(s)", nullptr, n)
                     .arg(p.x)
                     .arg(p.y)
                     .arg(r.paneSize.width())
                     .arg(r.paneSize.height())
                     .arg(model_.paneCount() > 1 ? (r.side == 0 ? tr(", pane A") : tr(", pane B")) : QString());
  if (p.edge) text += tr(" — on a triangle edge (rasterisation may differ)");
  if (p.depthTie) text += tr(" — two at one depth (order undefined)");
  const auto to8 = [](float c) { return static_cast<int>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
  const QColor exact(to8(p.exactColor.r), to8(p.exactColor.g), to8(p.exactColor.b));
  text += tr(". Exact colour %1").arg(exact.name());
  // Under "volume" the exact colour is the surfaces' and the medium's together.
  const QColor reference = p.volume ? QColor(to8(p.volumeColor.r), to8(p.volumeColor.g), to8(p.volumeColor.b))
                           : p.zthickness
                               ? QColor(to8(p.zthicknessColor.r), to8(p.zthicknessColor.g), to8(p.zthicknessColor.b))
                               : exact;
  if (p.zthickness) {
    text += tr(" (over), %1 with z-thickness %2 (%3 of the surfaces blend with a neighbour)")
                .arg(reference.name())
                .arg(p.thickness, 0, 'g', 4)
                .arg(p.zthicknessBlended);
  }
  if (p.volume) {
    double medium = 0.0;
    std::vector<double> byVolume(p.volumeNames.size(), 0.0);
    for (const mfr::ProbeMedium& m : p.medium) {
      medium += m.weight;
      for (std::size_t v = 0; v < byVolume.size() && v < m.weightByVolume.size(); ++v)
        byVolume[v] += m.weightByVolume[v];
    }
    // Several volumes: each one's part of the medium's share.
    QStringList parts;
    if (byVolume.size() > 1)
      for (std::size_t v = 0; v < byVolume.size(); ++v)
        parts << tr("%1 %2 %").arg(QString::fromStdString(p.volumeNames[v]),
                                   QString::number(100.0 * byVolume[v], 'f', 1));
    text += tr(" (surfaces only), %1 with the volume (the medium's share %2 %%3)")
                .arg(reference.name())
                .arg(QString::number(100.0 * medium, 'f', 1))
                .arg(parts.isEmpty() ? QString() : QStringLiteral(": ") + parts.join(QStringLiteral(", ")));
  }
  if (r.shown) {
    const int diff =
        std::max({std::abs(r.shown->red() - reference.red()), std::abs(r.shown->green() - reference.green()),
                  std::abs(r.shown->blue() - reference.blue())});
    text += tr(", shown %1 (largest difference %2/255)").arg(r.shown->name()).arg(diff);
  }
  text += QStringLiteral(".");
  if (p.captured) {
    text += tr(" %1 holds %2 of them").arg(r.method).arg(p.heldCount());
    if (p.methodCount != p.heldCount()) text += tr(" (%1 in all)").arg(p.methodCount);
    text += QStringLiteral(".");
    if (p.hybrid) {
      // What the method's split costs here: its core exact, its tail averaged.
      const QColor hybrid(to8(p.hybridColor.r), to8(p.hybridColor.g), to8(p.hybridColor.b));
      const int cost = std::max({std::abs(hybrid.red() - exact.red()), std::abs(hybrid.green() - exact.green()),
                                 std::abs(hybrid.blue() - exact.blue())});
      text += tr(" Hybrid colour %1 (core %2, tail %3; largest difference from exact %4/255).")
                  .arg(hybrid.name())
                  .arg(p.heldCount())
                  .arg(n - static_cast<int>(p.heldCount()))
                  .arg(cost);
    }
  } else {
    text += tr(" %1 keeps no per-pixel lists.").arg(r.method);
  }
  summary_->setText(text);

  const ContentSizedSectionsHeld held(table_->horizontalHeader());  // a deep pixel has thousands of rows
  table_->setRowCount(n + 1);
  // The probe's ids are the drawn scene's: a section's volume slices come after the scene's parts.
  const auto& objects = model_.drawnScene().objects;
  const Qt::Alignment right = Qt::AlignRight | Qt::AlignVCenter;
  for (int i = 0; i < n; ++i) {
    const mfr::ProbeFragment& f = p.fragments[static_cast<std::size_t>(i)];
    const std::uint32_t id = f.fragment.objectId;
    const QColor colour = rgbOf(f.fragment.color);
    table_->setItem(i, Index, item(QString::number(i + 1), right));
    table_->setItem(i, EyeDepth, item(QString::number(f.eyeDepth, 'g', 6), right));
    QTableWidgetItem* part = item(id < objects.size() ? QString::fromStdString(objects[id].name) : QStringLiteral("?"));
    // The scene's part, for partChosen: not a volume's slice (its id lies past the scene's parts).
    part->setData(Qt::UserRole, id < model_.scene().objects.size() ? static_cast<int>(id) : -1);
    table_->setItem(i, Part, part);
    QTableWidgetItem* swatch = item(colour.name());
    swatch->setBackground(colour);
    swatch->setForeground(colour.lightnessF() > 0.5 ? Qt::black : Qt::white);
    table_->setItem(i, Colour, swatch);
    table_->setItem(i, Alpha, item(QString::number((f.fragment.color >> 24) / 255.0, 'f', 3), right));
    table_->setItem(i, Faces, item(f.fragment.frontFacing ? tr("front") : tr("back")));
    table_->setItem(i, Share, item(QString::number(100.0 * f.weight, 'f', 1) + QStringLiteral(" %"), right));
    table_->setItem(i, Held,
                    item(!p.captured ? QStringLiteral("—")
                         : p.hybrid  ? (f.held ? tr("core") : tr("tail"))
                                     : (f.held ? tr("held") : tr("dropped"))));
    table_->setItem(
        i, HybridShare,
        item(p.hybrid ? QString::number(100.0 * f.hybridWeight, 'f', 1) + QStringLiteral(" %") : QString(), right));
    table_->setItem(
        i, VolumeShare,
        item(p.volume ? QString::number(100.0 * f.volumeWeight, 'f', 1) + QStringLiteral(" %") : QString(), right));
    table_->setItem(
        i, ZThicknessShare,
        item(p.zthickness ? QString::number(100.0 * f.zthicknessWeight, 'f', 1) + QStringLiteral(" %") : QString(),
             right));
    table_->setItem(i, FieldValue,
                    item(f.hasValue ? QStringLiteral("%1 %2")
                                          .arg(QString::fromStdString(objects[id].material.fieldColors->field))
                                          .arg(static_cast<double>(f.value), 0, 'g', 6)
                                    : QString(),
                         right));
    if (p.captured && !f.held && !p.hybrid)  // dropped; a tail fragment still counts
      for (int c = 0; c < ColumnCount; ++c)
        if (c != Colour) table_->item(i, c)->setForeground(palette().color(QPalette::Disabled, QPalette::Text));
  }
  const QColor bg(to8(model_.scene().background.r), to8(model_.scene().background.g), to8(model_.scene().background.b));
  for (int c = 0; c < ColumnCount; ++c) table_->setItem(n, c, item(QString()));
  table_->item(n, Part)->setText(tr("background"));
  table_->item(n, Colour)->setText(bg.name());
  table_->item(n, Colour)->setBackground(bg);
  table_->item(n, Colour)->setForeground(bg.lightnessF() > 0.5 ? Qt::black : Qt::white);
  table_->item(n, Share)->setText(QString::number(100.0 * p.transmittance, 'f', 1) + QStringLiteral(" %"));
  table_->item(n, Share)->setTextAlignment(right);
  if (p.hybrid) {
    table_->item(n, HybridShare)->setText(QString::number(100.0 * p.hybridBackground, 'f', 1) + QStringLiteral(" %"));
    table_->item(n, HybridShare)->setTextAlignment(right);
  }
  table_->setColumnHidden(HybridShare, !p.hybrid);
  if (p.volume) {
    table_->item(n, VolumeShare)->setText(QString::number(100.0 * p.volumeBackground, 'f', 1) + QStringLiteral(" %"));
    table_->item(n, VolumeShare)->setTextAlignment(right);
  }
  table_->setColumnHidden(VolumeShare, !p.volume);
  if (p.zthickness) {
    table_->item(n, ZThicknessShare)
        ->setText(QString::number(100.0 * p.zthicknessBackground, 'f', 1) + QStringLiteral(" %"));
    table_->item(n, ZThicknessShare)->setTextAlignment(right);
  }
  table_->setColumnHidden(ZThicknessShare, !p.zthickness);
  table_->setColumnHidden(FieldValue, std::none_of(p.fragments.begin(), p.fragments.end(),
                                                   [](const mfr::ProbeFragment& f) { return f.hasValue; }));
}
