#include "plugin_manager.hpp"

#include <QCoreApplication>
#include <QDir>
#include <QJsonArray>
#include <QJsonObject>
#include <QJsonValue>
#include <QLibrary>
#include <QPluginLoader>

#include "viewer_plugin.hpp"

namespace {

QString jsonTypeName(const QJsonValue& value) {
  switch (value.type()) {
    case QJsonValue::Null:
      return QStringLiteral("null");
    case QJsonValue::Bool:
      return QStringLiteral("a boolean");
    case QJsonValue::Double:
      return QStringLiteral("a number");
    case QJsonValue::String:
      return QStringLiteral("a string");
    case QJsonValue::Array:
      return QStringLiteral("an array");
    case QJsonValue::Object:
      return QStringLiteral("an object");
    case QJsonValue::Undefined:
      break;
  }
  return QStringLiteral("nothing");
}

}  // namespace

QString pluginSettingsProblem(const MfrViewerPlugin& plugin, const QJsonObject& given) {
  const QJsonObject own = plugin.saveSettings();
  if (own.isEmpty()) return {};  // a plugin without a panel (or settings) says nothing to check by
  for (auto it = given.begin(); it != given.end(); ++it) {
    if (!own.contains(it.key()))
      return QStringLiteral("unknown key '%1' (known: %2)").arg(it.key(), own.keys().join(QStringLiteral(", ")));
    const QJsonValue expected = own.value(it.key());
    if (expected.isNull()) continue;  // a value saved as null (Qt's NaN) tells no type
    if (it.value().type() != expected.type())
      return QStringLiteral("'%1': %2, expected %3").arg(it.key(), jsonTypeName(it.value()), jsonTypeName(expected));
    if (expected.isArray() && !expected.toArray().isEmpty()) {
      const QJsonArray values = it.value().toArray();
      const QJsonValue element = expected.toArray().first();
      for (qsizetype i = 0; i < values.size(); ++i)
        if (values[i].type() != element.type())
          return QStringLiteral("'%1'[%2]: %3, expected %4")
              .arg(it.key())
              .arg(i)
              .arg(jsonTypeName(values[i]), jsonTypeName(element));
    }
  }
  return {};
}

QStringList PluginManager::searchPaths() {
  QStringList paths;
  const QString env = qEnvironmentVariable("MFR_PLUGIN_PATH");
  for (const QString& p : env.split(QLatin1Char(':'), Qt::SkipEmptyParts)) paths << QDir(p).absolutePath();
  const QDir exe(QCoreApplication::applicationDirPath());
  paths << exe.absoluteFilePath(QStringLiteral("plugins"))
        << QDir::cleanPath(exe.absoluteFilePath(QStringLiteral(MFRVIEW_PLUGINS_FROM_BINDIR)));
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
        record.error = QCoreApplication::translate("PluginManager", "not an mfrview plugin (interface %1)")
                           .arg(MfrViewerPlugin_iid);
      } else if (seenIds.contains(plugin->id())) {
        // The same plugin in two folders: the first one found (MFR_PLUGIN_PATH) wins.
        record.error =
            QCoreApplication::translate("PluginManager", "duplicate of plugin '%1' loaded earlier").arg(plugin->id());
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
