#pragma once
// The CSG plugin: builds and edits the scene's constructive-solid-geometry tree and shows it with
// the operation "csg" (image-space CSG on the sorted fragment lists, docs/methods.md).
#include <QObject>
#include <QPointer>

#include "viewer_plugin.hpp"

class CsgPanel;

class CsgPlugin final : public QObject, public MfrViewerPlugin {
  Q_OBJECT
  Q_PLUGIN_METADATA(IID MfrViewerPlugin_iid FILE "csg.json")
  Q_INTERFACES(MfrViewerPlugin)

 public:
  [[nodiscard]] QString id() const override { return QStringLiteral("csg"); }
  [[nodiscard]] QString name() const override { return tr("CSG"); }
  [[nodiscard]] QString description() const override;
  QWidget* createPanel(ViewerContext& context, QWidget* parent) override;
  [[nodiscard]] QJsonObject saveSettings() const override;
  void loadSettings(const QJsonObject& settings) override;

 private:
  QPointer<CsgPanel> panel_;
};
