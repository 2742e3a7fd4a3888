#include "ghosting_plugin.hpp"

#include "ghosting_panel.hpp"

QString GhostingPlugin::description() const {
  return tr(
      "Ghosting panel: blend intersecting or coincident surfaces by z-thickness (operation zthickness) with a "
      "thickness slider, and ghost the parts around the ones in focus.");
}

QWidget* GhostingPlugin::createPanel(ViewerContext& context, QWidget* parent) {
  panel_ = new GhostingPanel(context, parent);
  return panel_;
}

QJsonObject GhostingPlugin::saveSettings() const {
  return panel_ ? panel_->saveSettings() : QJsonObject{};
}

void GhostingPlugin::loadSettings(const QJsonObject& settings) {
  if (panel_) panel_->loadSettings(settings);
}
