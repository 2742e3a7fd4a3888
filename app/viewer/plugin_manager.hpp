#pragma once
// Finds and loads mfrview plugins: every shared library in $MFR_PLUGIN_PATH (colon-separated
// folders, searched first) and in `plugins` beside the executable (also ../lib/mfrview/plugins
// for an installed layout). Failures are kept with their reason for Help → Plugins.
#include <QString>
#include <QStringList>

#include <vector>

class MfrViewerPlugin;

struct PluginRecord {
  QString file;
  QString id, name, description;
  MfrViewerPlugin* plugin = nullptr;  // owned by QPluginLoader's root instance; null on failure
  QString error;
};

class PluginManager {
 public:
  void loadAll();
  [[nodiscard]] const std::vector<PluginRecord>& records() const { return records_; }
  [[nodiscard]] static QStringList searchPaths();

 private:
  std::vector<PluginRecord> records_;
};
