#pragma once
// The budget plugin: fits a transparency method into a GPU memory budget and shows what the
// budget costs — memory used against it, fragments captured, and the scene's depth complexity
// with the chosen k marked.
#include <QObject>
#include <QPointer>

#include "viewer_plugin.hpp"

class BudgetPanel;

class BudgetPlugin final : public QObject, public MfrViewerPlugin {
  Q_OBJECT
  Q_PLUGIN_METADATA(IID MfrViewerPlugin_iid FILE "budget.json")
  Q_INTERFACES(MfrViewerPlugin)

 public:
  [[nodiscard]] QString id() const override { return QStringLiteral("budget"); }
  [[nodiscard]] QString name() const override { return tr("Memory budget"); }
  [[nodiscard]] QString description() const override;
  QWidget* createPanel(ViewerContext& context, QWidget* parent) override;
  [[nodiscard]] QJsonObject saveSettings() const override;
  void loadSettings(const QJsonObject& settings) override;
  [[nodiscard]] std::map<std::string, std::string> exportParams(QSize size,
                                                                const std::map<std::string, std::string>* tried,
                                                                const mfr::Stats* measured) const override;

 private:
  QPointer<BudgetPanel> panel_;
};
