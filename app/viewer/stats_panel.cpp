#include "stats_panel.hpp"

#include <QHeaderView>
#include <QLocale>
#include <QTreeWidget>
#include <QVBoxLayout>

#include "viewer_model.hpp"

QString formatBytes(quint64 bytes) {
  if (bytes >= (1ull << 30)) return QStringLiteral("%1 GiB").arg(static_cast<double>(bytes) / (1ull << 30), 0, 'f', 2);
  if (bytes >= (1ull << 20)) return QStringLiteral("%1 MiB").arg(static_cast<double>(bytes) / (1ull << 20), 0, 'f', 2);
  if (bytes >= (1ull << 10)) return QStringLiteral("%1 KiB").arg(static_cast<double>(bytes) / (1ull << 10), 0, 'f', 1);
  return QStringLiteral("%1 B").arg(bytes);
}

StatsPanel::StatsPanel(ViewerModel& model, QWidget* parent) : QWidget(parent), model_(model) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  tree_ = new QTreeWidget;
  tree_->setObjectName(QStringLiteral("statsTree"));
  tree_->setColumnCount(2);
  tree_->setHeaderLabels({tr("Statistic"), tr("Value")});
  tree_->header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
  tree_->setRootIsDecorated(true);
  tree_->setAlternatingRowColors(true);
  layout->addWidget(tree_);
  connect(&model_, &ViewerModel::frameRendered, this, &StatsPanel::showStats);
  // A CPU method's first frame of a new scene takes seconds: the previous scene's numbers stood
  // under the new scene's name until then (a bug hunt). A GPU frame follows at once.
  connect(&model_, &ViewerModel::sceneLoaded, this, [this] {
    if (!model_.isCpuMethod(model_.method())) return;
    tree_->clear();
    new QTreeWidgetItem(tree_, {tr("Frame"), tr("being computed for this scene")});
  });
  // No numbers of the last frame drawn under a frame that cannot be drawn.
  connect(&model_, &ViewerContext::frameErrorChanged, this, [this] {
    const QString error = model_.frameError();
    if (error.isEmpty()) return;
    tree_->clear();
    auto* item = new QTreeWidgetItem(tree_, {tr("No frame"), error});
    item->setToolTip(1, error);
  });
}

void StatsPanel::showStats() {
  const mfr::Stats& s = model_.stats();
  const QLocale locale;
  const auto count = [&](quint64 n) { return locale.toString(n); };
  tree_->setUpdatesEnabled(false);
  tree_->clear();
  const auto group = [&](const QString& title) {
    auto* item = new QTreeWidgetItem(tree_, {title});
    QFont bold = item->font(0);
    bold.setBold(true);
    item->setFont(0, bold);
    item->setExpanded(true);
    return item;
  };
  const auto row = [](QTreeWidgetItem* parent, const QString& name, const QString& value) {
    new QTreeWidgetItem(parent, {name, value});
  };

  QTreeWidgetItem* frame = group(tr("Frame"));
  row(frame, tr("Method"), QString::fromStdString(s.method));
  row(frame, tr("Operation"), QString::fromStdString(s.operation));
  row(frame, tr("Image"), QStringLiteral("%1 × %2").arg(model_.paneSize().width()).arg(model_.paneSize().height()));
  row(frame, tr("Synchronisation"), QString::fromStdString(s.sync));
  row(frame, tr("Geometry passes"), QString::number(s.passes));
  if (s.kMax > 0)
    row(frame, tr("k range"),
        s.kMin == s.kMax ? QString::number(s.kMax) : QStringLiteral("%1 … %2").arg(s.kMin).arg(s.kMax));

  QTreeWidgetItem* memory = group(tr("Memory"));
  row(memory, tr("Allocated"), formatBytes(s.bytesAllocated));
  row(memory, tr("Used"),
      s.bytesAllocated ? QStringLiteral("%1 (%2 %)")
                             .arg(formatBytes(s.bytesUsed))
                             .arg(100.0 * s.bytesUsed / s.bytesAllocated, 0, 'f', 1)
                       : formatBytes(s.bytesUsed));

  QTreeWidgetItem* fragments = group(tr("Fragments"));
  row(fragments, tr("Generated"), count(s.fragmentsGenerated));
  row(fragments, tr("Stored"),
      s.fragmentsGenerated ? QStringLiteral("%1 (%2 %)")
                                 .arg(count(s.fragmentsStored))
                                 .arg(100.0 * s.fragmentsStored / s.fragmentsGenerated, 0, 'f', 1)
                           : count(s.fragmentsStored));
  row(fragments, tr("Dropped"), count(s.fragmentsDropped));
  row(fragments, tr("Overflow"), s.overflow ? tr("yes — %1 pixels").arg(count(s.overflowPixels)) : tr("no"));
  row(fragments, tr("Lock failures"), count(s.lockFailures));

  QTreeWidgetItem* times = group(tr("GPU time (ms)"));
  for (const auto& [pass, ms] : s.passTimesMs) row(times, QString::fromStdString(pass), QString::number(ms, 'f', 2));
  row(times, tr("Total"), QString::number(s.totalTimeMs(), 'f', 2));

  if (!s.notes.empty()) {
    QTreeWidgetItem* notes = group(tr("Notes"));
    for (const auto& [key, value] : s.notes) row(notes, QString::fromStdString(key), QString::fromStdString(value));
  }
  tree_->setUpdatesEnabled(true);
}
