#pragma once
// The CSG panel: the scene's parts as a checklist with Union / Intersection / Difference buttons
// that make a tree of the checked parts (in list order; a difference takes the others from the
// first), the tree as editable JSON (the scene file's "csg" form, for nested trees), and a switch
// that draws it with the operation "csg", choosing an A-buffer when the method cannot store the
// object ids the classification needs.
#include <QJsonObject>
#include <QWidget>

class QCheckBox;
class QLabel;
class QListWidget;
class QPlainTextEdit;
class ViewerContext;

class CsgPanel final : public QWidget {
  Q_OBJECT

 public:
  explicit CsgPanel(ViewerContext& context, QWidget* parent = nullptr);
  [[nodiscard]] QJsonObject saveSettings() const;
  void loadSettings(const QJsonObject& settings);

 private:
  void sceneChanged();
  void combineChecked(const QString& op);
  void applyText();
  void setShown(bool on);
  void showError(const QString& message);

  ViewerContext& context_;
  QCheckBox* show_ = nullptr;
  QListWidget* objects_ = nullptr;
  QPlainTextEdit* text_ = nullptr;
  QLabel* error_ = nullptr;
  QStringList names_;        // the object list's names, to rebuild it only when they change
  quint64 sceneSerial_ = 0;  // ViewerContext::sceneSerial of the scene the list shows
};
