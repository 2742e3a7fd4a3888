#include "plugin_manager.hpp"

#include <QCoreApplication>
#include <QDir>
#include <QLibrary>
#include <QPluginLoader>

#include "viewer_plugin.hpp"

QStringList PluginManager::searchPaths() {
  QStringList paths;
  const QString env = qEnvironmentVariable("MFR_PLUGIN_PATH");
  for (const QString& p : env.split(QLatin1Char(':'), Qt::SkipEmptyParts)) paths << QDir(p).absolutePath();
  const QDir exe(QCoreApplication::applicationDirPath());
  paths << exe.absoluteFilePath(QStringLiteral("plugins")) << exe.absoluteFilePath(QStringLiteral("../lib/mfrview/plugins"));
  paths.removeDuplicates();
  return paths;
}

void PluginManager::loadAll() {
  QStringList seenIds;
  for (const QString& folder : searchPaths()) {
    const QDir dir(folder);
    for (const QString& entry : dir.entryList(QDir::Files, QDir::Name)) {
      const QString file = dir.absoluteFilePath(entry);
      if (!QLibrary::isLibrary(file)) continue;
      PluginRecord record;
      record.file = file;
      QPluginLoader loader(file);
      QObject* instance = loader.instance();
      auto* plugin = qobject_cast<MfrViewerPlugin*>(instance);
      if (!instance) {
        record.error = loader.errorString();
      } else if (!plugin) {
        record.error = QCoreApplication::translate("PluginManager", "not an mfrview plugin (interface %1)").arg(MfrViewerPlugin_iid);
      } else if (seenIds.contains(plugin->id())) {
        // The same plugin in two folders: the first one found (MFR_PLUGIN_PATH) wins.
        record.error = QCoreApplication::translate("PluginManager", "duplicate of plugin '%1' loaded earlier").arg(plugin->id());
      } else {
        record.plugin = plugin;
        record.id = plugin->id();
        record.name = plugin->name();
        record.description = plugin->description();
        seenIds << record.id;
      }
      records_.push_back(record);
    }
  }
}
