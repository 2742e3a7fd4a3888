#pragma once
// The ghosting panel.
// - "Blend intersecting surfaces": switches the main view to the operation zthickness (back to the
//   previous operation when off), choosing abuffer-ll when the current method keeps no sorted
//   lists (peeling, WBOIT, MBOIT; ViewerContext::supportsOperation).
// - Thickness: a logarithmic slider in % of the scene's diagonal (0.05 % … 10 %) and a spin box in
//   scene units, both on ViewerContext::zThickness (shared with the method panel).
// - Ghosting: the parts as a checklist of parts in focus; "Ghost the other parts" sets every other
//   part to the ghost opacity (live while the slider moves) and, switched off, gives each ghosted
//   part the opacity it had before; "Restore opacities" brings back the opacities of the scene as
//   loaded. Opacities go through ViewerContext::setObjectOpacities: the scene tree's path, so every
//   pane (CPU images included) sees them. Isosurfaces added or removed keep the focus and ghosting
//   of the parts that stay, and new parts are ghosted too; another scene starts unghosted.
#include <QJsonObject>
#include <QMap>
#include <QWidget>

class QCheckBox;
class QDoubleSpinBox;
class QLabel;
class QListWidget;
class QSlider;
class ViewerContext;

class GhostingPanel final : public QWidget {
  Q_OBJECT

 public:
  // The thickness slider's range, in % of the scene's diagonal, and its steps.
  static constexpr double kMinPercent = 0.05;
  static constexpr double kMaxPercent = 10.0;
  static constexpr int kSliderSteps = 1000;
  static constexpr double kDefaultGhostOpacity = 0.15;
  // The method chosen when the current one cannot run zthickness.
  static constexpr const char* kBlendMethod = "abuffer-ll";

  explicit GhostingPanel(ViewerContext& context, QWidget* parent = nullptr);
  [[nodiscard]] QJsonObject saveSettings() const;
  void loadSettings(const QJsonObject& settings);

 private:
  void sceneChanged();
  void setBlend(bool on);
  void showBlendState();
  void showThickness();
  void thicknessFromSlider(int position);
  void applyGhosting();
  void restoreOpacities();
  [[nodiscard]] double diagonal() const;
  [[nodiscard]] double ghostOpacity() const;
  [[nodiscard]] bool isFocus(int objectId) const;
  [[nodiscard]] QStringList settingNames() const;  // each part's key in focus and ghosted
  [[nodiscard]] QStringList ownParts(const QStringList& names) const;

  ViewerContext& context_;
  QCheckBox* blend_ = nullptr;
  QLabel* blendNote_ = nullptr;
  QSlider* thicknessSlider_ = nullptr;
  QDoubleSpinBox* thickness_ = nullptr;
  QLabel* thicknessPercent_ = nullptr;
  QListWidget* parts_ = nullptr;
  QCheckBox* ghost_ = nullptr;
  QSlider* ghostSlider_ = nullptr;
  QLabel* ghostValue_ = nullptr;

  QStringList names_;          // the part list's names, to rebuild it only when they change
  quint64 sceneSerial_ = 0;    // ViewerContext::sceneSerial of the scene the list shows
  QString previousOperation_;  // before the blend switch went on
  QString previousMethod_;     // replaced by kBlendMethod when the switch went on, else empty
  QMap<int, double> saved_;    // ghosted parts: their opacity before ghosting, by object id
};
