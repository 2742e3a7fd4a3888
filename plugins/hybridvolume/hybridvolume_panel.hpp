#pragma once
// The Volume panel (plugin "hybridvolume").
// - "Show volume": shows the scene's volume and switches the main view to the operation volume,
//   choosing abuffer-sbuffer when the current method keeps no sorted lists
//   (ViewerContext::supportsOperation); off, it hides the volume and brings back the method and
//   operation it replaced.
// - Transfer function: a preset (mfr::transferPresetNames) or "Custom" (the function as loaded, or
//   one set elsewhere), mapped onto a window [min, max] of scalar values; an opacity scale on a
//   logarithmic slider multiplies the extinction (divides the unit distance); "As Loaded" brings
//   back the scene's own function. A strip previews the 256-entry table the renderers sample.
// - Step: a logarithmic slider (0.1× … 10× the default), a spin box in scene units and Default,
//   all on ViewerContext::volumeStep (shared with the method panel's Step row).
// - An info line: grid size, spacing, value range, and the last frame's step and GPU bytes (its
//   stats notes "volume step" and "volume (bytes)").
#include <QJsonObject>
#include <QWidget>

#include "mfr/scene/volume.hpp"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QSlider;
class ViewerContext;

class HybridVolumePanel final : public QWidget {
  Q_OBJECT

 public:
  // The method chosen when the current one cannot run the operation volume.
  static constexpr const char* kVolumeMethod = "abuffer-sbuffer";
  // Opacity scale: logarithmic slider over kMinScale … kMaxScale.
  static constexpr double kMinScale = 0.05;
  static constexpr double kMaxScale = 20.0;
  static constexpr int kSliderSteps = 1000;
  // Step slider: kMinStepFactor … kMaxStepFactor times the volume's default step (logarithmic).
  static constexpr double kMinStepFactor = 0.1;
  static constexpr double kMaxStepFactor = 10.0;

  explicit HybridVolumePanel(ViewerContext& context, QWidget* parent = nullptr);
  [[nodiscard]] QJsonObject saveSettings() const;
  void loadSettings(const QJsonObject& settings);

 private:
  void volumeChanged();
  void resetToCurrent();  // Custom, based on the context's function, its own window, scale 1
  void setShow(bool on);
  void showState();
  void applyTransfer();
  [[nodiscard]] mfr::TransferFunction composed() const;
  [[nodiscard]] double opacityScale() const;
  void showScaleValue();
  void showPreview();
  void showStep();
  void stepFromSlider(int position);
  void showInfo();

  ViewerContext& context_;
  QCheckBox* show_ = nullptr;
  QLabel* note_ = nullptr;
  QComboBox* preset_ = nullptr;
  QDoubleSpinBox* windowMin_ = nullptr;
  QDoubleSpinBox* windowMax_ = nullptr;
  QSlider* opacity_ = nullptr;
  QCheckBox* shade_ = nullptr;
  QLabel* opacityValue_ = nullptr;
  QLabel* preview_ = nullptr;
  QLabel* error_ = nullptr;
  QSlider* stepSlider_ = nullptr;
  QDoubleSpinBox* step_ = nullptr;
  QLabel* info_ = nullptr;
  QWidget* controls_ = nullptr;

  QString sceneKey_;               // the volume the panel was set up for
  mfr::TransferFunction base_;     // Custom's points (over their own range) and the unit distance at scale 1
  mfr::TransferFunction applied_;  // what the panel last set (another function: an edit from elsewhere)
  QString previousOperation_;      // replaced by "volume" when the switch went on, else empty
  QString previousMethod_;         // replaced by kVolumeMethod when the switch went on, else empty
};
