#include "hybridvolume_plugin.hpp"

#include "hybridvolume_panel.hpp"

QString HybridVolumePlugin::description() const {
  return tr(
      "Volume panel: show the scene's scalar volume between the sorted surfaces (operation volume), with a "
      "transfer-function preset, window, opacity scale, preview and editor (control points over a histogram of "
      "the values), and the ray-march step.");
}

QWidget* HybridVolumePlugin::createPanel(ViewerContext& context, QWidget* parent) {
  panel_ = new HybridVolumePanel(context, parent);
  return panel_;
}

QJsonObject HybridVolumePlugin::saveSettings() const {
  return panel_ ? panel_->saveSettings() : QJsonObject{};
}

void HybridVolumePlugin::loadSettings(const QJsonObject& settings) {
  if (panel_) panel_->loadSettings(settings);
}
