#pragma once
// The ghosting plugin: intersecting-surface comparison with the operation "zthickness" (z-thickness
// blending, Kim & Kye 2021: surfaces closer than a thickness blend instead of z-fighting) and
// ghosted views (context parts made faint around the parts in focus).
#include <QObject>
#include <QPointer>

#include "viewer_plugin.hpp"

class GhostingPanel;

class GhostingPlugin final : public QObject, public MfrViewerPlugin {
  Q_OBJECT
  Q_PLUGIN_METADATA(IID MfrViewerPlugin_iid FILE "ghosting.json")
  Q_INTERFACES(MfrViewerPlugin)

 public:
  [[nodiscard]] QString id() const override { return QStringLiteral("ghosting"); }
  [[nodiscard]] QString name() const override { return tr("Ghosting"); }
  [[nodiscard]] QString description() const override;
  QWidget* createPanel(ViewerContext& context, QWidget* parent) override;
  [[nodiscard]] QJsonObject saveSettings() const override;
  void loadSettings(const QJsonObject& settings) override;

 private:
  QPointer<GhostingPanel> panel_;
};
