#pragma once
// Finds and loads mfrview plugins: every shared library in $MFR_PLUGIN_PATH (colon-separated
// folders, searched first), in `plugins` beside the executable (the build tree), and in the
// installed layout's folder (../lib/mfrview/plugins from bin/: cmake/MfrInstall.cmake). Failures are kept with their
// reason for Help → Plugins.
#include <QString>
#include <QStringList>

#include <vector>

class MfrViewerPlugin;
class QJsonObject;

// Why settings given for a plugin (--plugin-settings, a session's "plugins") cannot be its own:
// a key its saveSettings() does not write ("unknown key 'x' (known: …)"), or a value of another
// JSON type than the one it writes there, element by element in an array it writes non-empty
// ("'budget_mib': a string, expected a number"); empty when none. Keys it writes that are absent
// are fine (loadSettings keeps their defaults). Without this, loadSettings read a wrong type as
// the default ("budget_mib": "2" rendered at 16 MiB) and ignored a misspelt key.
[[nodiscard]] QString pluginSettingsProblem(const MfrViewerPlugin& plugin, const QJsonObject& given);

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
