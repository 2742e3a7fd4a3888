#include "csg_plugin.hpp"

#include "csg_panel.hpp"

QString CsgPlugin::description() const {
  return tr(
      "CSG panel: combine the scene's closed parts by union, intersection and difference, edit the tree, "
      "and draw it as solids from the sorted fragment lists (operation csg).");
}

QWidget* CsgPlugin::createPanel(ViewerContext& context, QWidget* parent) {
  panel_ = new CsgPanel(context, parent);
  return panel_;
}

QJsonObject CsgPlugin::saveSettings() const {
  return panel_ ? panel_->saveSettings() : QJsonObject{};
}

void CsgPlugin::loadSettings(const QJsonObject& settings) {
  if (panel_) panel_->loadSettings(settings);
}
