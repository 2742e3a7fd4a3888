#include "budget_plugin.hpp"

#include "budget_panel.hpp"

QString BudgetPlugin::description() const {
  return tr(
      "Variable-k budget panel: a memory slider driving the method's memory parameter, "
      "memory used against the budget, fragments captured and the depth-complexity histogram.");
}

QWidget* BudgetPlugin::createPanel(ViewerContext& context, QWidget* parent) {
  panel_ = new BudgetPanel(context, parent);
  return panel_;
}

QJsonObject BudgetPlugin::saveSettings() const {
  return panel_ ? panel_->saveSettings() : QJsonObject{};
}

std::map<std::string, std::string> BudgetPlugin::exportParams(QSize size,
                                                              const std::map<std::string, std::string>* tried,
                                                              const mfr::Stats* measured) const {
  return panel_ ? panel_->exportParams(size, tried, measured) : std::map<std::string, std::string>{};
}

void BudgetPlugin::loadSettings(const QJsonObject& settings) {
  if (panel_) panel_->loadSettings(settings);
}
