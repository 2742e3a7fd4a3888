#pragma once
// The statistics dock: everything mfr::Stats reports about the last frame.
#include <QWidget>

class QTreeWidget;
class ViewerModel;

class StatsPanel final : public QWidget {
  Q_OBJECT

 public:
  explicit StatsPanel(ViewerModel& model, QWidget* parent = nullptr);

 private:
  void showStats();

  ViewerModel& model_;
  QTreeWidget* tree_ = nullptr;
};

// "12.3 MiB", "512 KiB", "96 B".
QString formatBytes(quint64 bytes);
