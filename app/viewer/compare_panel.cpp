#include "compare_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHeaderView>
#include <QLabel>
#include <QSignalBlocker>
#include <QSlider>
#include <QScrollBar>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>

#include "method_panel.hpp"
#include "viewer_model.hpp"

namespace {

constexpr int kSplitSteps = 1000;

}  // namespace

ComparePanel::ComparePanel(ViewerModel& model, QWidget* parent) : QWidget(parent), model_(model) {
  setObjectName(QStringLiteral("comparePanel"));
  auto* layout = new QVBoxLayout(this);
  enabled_ = new QCheckBox(tr("Compare two methods (C)"));
  enabled_->setObjectName(QStringLiteral("compareEnabled"));
  layout->addWidget(enabled_);

  auto* form = new QFormLayout;
  layout_ = new QComboBox;
  layout_->setObjectName(QStringLiteral("compareLayout"));
  layout_->addItem(tr("Side by side"), static_cast<int>(CompareLayout::SideBySide));
  layout_->addItem(tr("Split (drag the line)"), static_cast<int>(CompareLayout::Split));
  split_ = new QSlider(Qt::Horizontal);
  split_->setObjectName(QStringLiteral("compareSplit"));
  split_->setRange(0, kSplitSteps);
  display_ = new QComboBox;
  display_->setObjectName(QStringLiteral("compareDisplay"));
  display_->addItem(tr("Images"), static_cast<int>(CompareDisplay::Images));
  display_->addItem(tr("FLIP error heat map"), static_cast<int>(CompareDisplay::FlipError));
  display_->addItem(tr("|difference| heat map"), static_cast<int>(CompareDisplay::Difference));
  form->addRow(tr("Layout"), layout_);
  form->addRow(tr("Split"), split_);
  form->addRow(tr("Show"), display_);
  layout->addLayout(form);

  metrics_ = new QTableWidget(2, 4);
  metrics_->setObjectName(QStringLiteral("compareMetrics"));
  metrics_->setHorizontalHeaderLabels({tr("Method"), tr("RMSE"), tr("FLIP mean"), tr("FLIP max")});
  metrics_->setVerticalHeaderLabels({QStringLiteral("A"), QStringLiteral("B")});
  metrics_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  metrics_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  metrics_->horizontalHeader()->setStretchLastSection(true);
  // Both rows always in sight, with room kept for the scroll bar a narrow dock gives the columns.
  metrics_->setVerticalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  metrics_->setFixedHeight(metrics_->horizontalHeader()->sizeHint().height() +
                           2 * metrics_->verticalHeader()->defaultSectionSize() +
                           metrics_->horizontalScrollBar()->sizeHint().height() + 2 * metrics_->frameWidth());
  layout->addWidget(metrics_);
  auto* note =
      new QLabel(tr("Against the exact image of the same size (the oracle's “over” of every fragment). "
                    "RMSE over RGB in [0, 1]; FLIP: mean and max per-pixel LDR-FLIP error (0 = "
                    "identical, 1 = most different), 67 pixels per degree."));
  note->setWordWrap(true);
  note->setStyleSheet(QStringLiteral("color: palette(mid);"));
  layout->addWidget(note);

  auto* second = new QGroupBox(tr("Method B"));
  auto* secondLayout = new QVBoxLayout(second);
  secondLayout->setContentsMargins(0, 0, 0, 0);
  secondLayout->addWidget(new MethodPanel(model_, 1));
  layout->addWidget(second);
  layout->addStretch(1);

  connect(enabled_, &QCheckBox::toggled, &model_, &ViewerModel::setCompareEnabled);
  connect(layout_, &QComboBox::currentIndexChanged, this,
          [this](int index) { model_.setCompareLayout(static_cast<CompareLayout>(layout_->itemData(index).toInt())); });
  connect(split_, &QSlider::valueChanged, this,
          [this](int value) { model_.setCompareSplit(static_cast<double>(value) / kSplitSteps); });
  connect(display_, &QComboBox::currentIndexChanged, this, [this](int index) {
    model_.setCompareDisplay(static_cast<CompareDisplay>(display_->itemData(index).toInt()));
  });
  connect(&model_, &ViewerModel::compareChanged, this, [this] {
    showSettings();
    showMetrics();
  });
  connect(&model_, &ViewerModel::metricsReady, this, &ComparePanel::showMetrics);
  connect(&model_, &ViewerModel::sideChanged, this, &ComparePanel::showMetrics);
  connect(&model_, &ViewerModel::viewChanged, this, &ComparePanel::showMetrics);
  connect(&model_, &ViewerModel::sceneChanged, this, &ComparePanel::showMetrics);
  showSettings();
  showMetrics();
}

void ComparePanel::showSettings() {
  const QSignalBlocker a(enabled_), b(layout_), c(split_), d(display_);
  enabled_->setChecked(model_.compareEnabled());
  layout_->setCurrentIndex(layout_->findData(static_cast<int>(model_.compareLayout())));
  split_->setValue(static_cast<int>(std::lround(model_.compareSplit() * kSplitSteps)));
  split_->setEnabled(model_.compareLayout() == CompareLayout::Split);
  // The display too (D and sessions set it; the combo kept "Images" under a heat map: a bug hunt).
  display_->setCurrentIndex(display_->findData(static_cast<int>(model_.compareDisplay())));
}

void ComparePanel::showMetrics() {
  for (int side = 0; side < kSides; ++side) {
    const PaneMetrics& m = model_.metrics(side);
    QStringList cells{model_.methodOf(side), QStringLiteral("—"), QStringLiteral("—"), QStringLiteral("—")};
    if (!model_.compareEnabled()) {
      cells[1] = tr("(off)");
    } else if (!model_.metricsCurrent(side)) {
      cells[1] = tr("computing…");
    } else if (!m.valid) {
      cells[1] = m.error;
    } else {
      cells[1] = QString::number(m.rmse, 'f', 5);
      cells[2] = QString::number(m.flip.mean, 'f', 4);
      cells[3] = QString::number(m.flip.max, 'f', 3);
    }
    for (int column = 0; column < 4; ++column) {
      QTableWidgetItem* item = metrics_->item(side, column);
      if (!item) metrics_->setItem(side, column, item = new QTableWidgetItem);
      item->setText(cells[column]);
    }
  }
}
