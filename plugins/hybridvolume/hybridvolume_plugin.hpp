#pragma once
// The hybridvolume plugin: a scalar volume composited exactly with the sorted surface fragments
// (operation "volume", Kainz et al. 2009): show it, edit its transfer function and ray-march step.
#include <QObject>
#include <QPointer>

#include "viewer_plugin.hpp"

class HybridVolumePanel;

class HybridVolumePlugin final : public QObject, public MfrViewerPlugin {
  Q_OBJECT
  Q_PLUGIN_METADATA(IID MfrViewerPlugin_iid FILE "hybridvolume.json")
  Q_INTERFACES(MfrViewerPlugin)

 public:
  [[nodiscard]] QString id() const override { return QStringLiteral("hybridvolume"); }
  [[nodiscard]] QString name() const override { return tr("Volume"); }
  [[nodiscard]] QString description() const override;
  QWidget* createPanel(ViewerContext& context, QWidget* parent) override;
  [[nodiscard]] QJsonObject saveSettings() const override;
  void loadSettings(const QJsonObject& settings) override;

 private:
  QPointer<HybridVolumePanel> panel_;
};
