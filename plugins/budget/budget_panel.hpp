#pragma once
// The budget panel. The slider sets a memory budget M (MiB) and the panel turns it into the
// current method's memory parameter:
//   budget_mib (kplus-dynamic)            M itself — the method chooses k per frame within it;
//   pool + pool_mib (A-buffers)           a fixed node pool of M minus the per-pixel heads;
//   k / slots (k-buffers, fixed arrays)   the largest k whose buffers fit, from a linear model
//                                         bytes(k) = a·k + b fitted to the frames' Stats
//                                         (a starts at 8 bytes per slot per pixel).
// A frame that still exceeds M refits the model and tries again (a few times at most), so the
// settled frame stays within budget whenever the method's smallest setting fits.
//
// The methods offered are every registered GPU method with one of those parameters (fkb, vkb,
// dkb … appear as soon as the registry has them), plus CPU methods besides the oracle (such as
// optimal-k), computed on demand off the GUI thread and given budget_mib like kplus-dynamic.
// The panel also shows the frame's RMSE and FLIP against the exact image once the view is at
// rest, the robustness ratio R_h of methods that have one (kplus-dynamic) and a switch for the
// k(p) map over the image.
#include <QJsonObject>
#include <QSize>
#include <QWidget>

#include <cstdint>
#include <map>
#include <string>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QProgressBar;
class QSlider;
class QSpinBox;
class QTimer;
class HistogramWidget;
class ViewerContext;
namespace mfr {
struct MethodInfo;
struct Stats;
}  // namespace mfr

class BudgetPanel final : public QWidget {
  Q_OBJECT

 public:
  BudgetPanel(ViewerContext& context, QWidget* parent = nullptr);
  [[nodiscard]] QJsonObject saveSettings() const;
  void loadSettings(const QJsonObject& settings);
  [[nodiscard]] int budgetMiB() const;
  // MfrViewerPlugin::exportParams: the driven parameter fitted to an exported image of `size`.
  [[nodiscard]] std::map<std::string, std::string> exportParams(QSize size,
                                                                const std::map<std::string, std::string>* tried,
                                                                const mfr::Stats* measured) const;

 protected:
  // The frame's quality is listened for only while the panel shows: the viewer reads each frame
  // back while anyone listens (ViewerModel::wantsFrameImage), a GPU stall a hidden panel need not cost.
  void showEvent(QShowEvent* event) override;
  void hideEvent(QHideEvent* event) override;

 private:
  enum class Knob { None, Budget, Pool, Slots };
  struct Driver {
    Knob knob = Knob::None;
    std::string param;  // budget_mib, pool_mib, k or slots
    long long minValue = 1, maxValue = 1;
  };
  [[nodiscard]] Driver driverFor(const QString& method) const;
  void setBudget(int mib);
  void applyBudget();
  // The memory model of the current method scaled to an image of `pixels` (bytes per slot and
  // fixed bytes of the slot methods, bytes besides the pool of the A-buffers), and the parameter
  // values that fit the budget under it.
  struct Model {
    double perSlot = 0.0, fixed = 0.0, poolOverhead = 0.0;
  };
  [[nodiscard]] Model modelAt(double pixels) const;
  [[nodiscard]] std::map<std::string, std::string> paramsFor(const Driver& d, const Model& m) const;
  void frameRendered();
  void showFrame();
  void methodChanged();
  void showKnob();  // what the budget drives, and whether it does yet
  void showRobustness();
  void showQuality();
  QString qualityToolTip(const QLabel* label, const QString& reason) const;

  ViewerContext& ctx_;
  QComboBox* methodCombo_ = nullptr;
  QSlider* slider_ = nullptr;
  QSpinBox* spin_ = nullptr;
  QLabel* knobLabel_ = nullptr;
  QProgressBar* memoryBar_ = nullptr;
  QLabel* memoryLabel_ = nullptr;
  QLabel* capturedLabel_ = nullptr;
  QLabel* kLabel_ = nullptr;
  QLabel* exactLabel_ = nullptr;  // the method's "exact at" note
  HistogramWidget* histogram_ = nullptr;
  QTimer* histogramTimer_ = nullptr;
  QDoubleSpinBox* robustness_ = nullptr;
  QSlider* robustnessSlider_ = nullptr;
  QWidget* robustnessRow_ = nullptr;
  QLabel* robustnessLabel_ = nullptr;
  QLabel* rmseLabel_ = nullptr;
  QLabel* flipLabel_ = nullptr;
  QTimer* qualityTimer_ = nullptr;
  QMetaObject::Connection qualityListened_;
  QCheckBox* kMapOverlay_ = nullptr;

  bool driving_ = false;  // the slider has been used: the budget owns the method's parameter
  int corrections_ = 0;   // refits after an over-budget frame, per budget change
  // Memory model of the current method and image size, from measured frames.
  struct Fit {
    std::string key;                           // method@WxH
    std::map<long long, std::uint64_t> bytes;  // parameter value → bytes allocated
    double poolOverhead = -1;                  // bytes besides the pool (A-buffers)
  } fit_;
  // Bytes measured by the renders of one export, by the driven parameter's value (exportParams).
  mutable std::map<long long, std::uint64_t> exportTries_;
};
