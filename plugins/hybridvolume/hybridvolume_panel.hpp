#pragma once
// The Volume panel (plugin "hybridvolume").
// - Volume (only for a scene with several): which volume the controls show and edit
//   (ViewerContext::setCurrentVolume); up to four are drawn at once, their media mixed.
// - "Show volume": shows the scene's volume and switches the main view to the operation volume,
//   choosing abuffer-sbuffer when the current method keeps no sorted lists
//   (ViewerContext::supportsOperation); off, it hides the volume and brings back the method and
//   operation it replaced.
// - Transfer function: a preset (mfr::transferPresetNames) or "Custom" (the function as loaded, one
//   set elsewhere, or the editor's points), mapped onto a window [min, max] of scalar values; an
//   opacity scale on a logarithmic slider multiplies the extinction (divides the unit distance);
//   "As Loaded" brings back the scene's own function. A strip previews the 256-entry table the
//   renderers sample.
// - The editor (TransferFunctionEditor) shows the function applied, over the window, on a histogram
//   of the volume, and edits its points; under it the selected point's value, opacity and colour
//   in spin boxes. An edit switches the preset to Custom with the edited points as its own (their
//   ends are the window's, so they apply unchanged; a later window stretches them) and applies them
//   live. The points' opacities are those of the scene's unit distance: the opacity scale stays a
//   separate factor on the extinction, so editing never moves the scale and the scale never moves
//   the points.
// - Step: a logarithmic slider (0.1× … 10× the default), a spin box in scene units and Default,
//   all on ViewerContext::volumeStep (shared with the method panel's Step row).
// - Isosurfaces: values (and an opacity) of the volume's isosurfaces, made as parts of their own
//   (ViewerContext::setIsosurfaces); the volume is hidden when they are made, and the method and
//   operation "Show volume" replaced come back; a refusal is shown under them.
// - An info line: grid size, spacing, value range, and the last frame's step and GPU bytes (its
//   stats notes "volume step" and "volume (bytes)").
#include <QMap>
#include <QJsonObject>
#include <QWidget>

#include <optional>

#include "mfr/scene/volume.hpp"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QSlider;
class TransferFunctionEditor;
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
  [[nodiscard]] QJsonObject noVolumeSettings() const;
  [[nodiscard]] QJsonObject saveSettings() const;
  void loadSettings(const QJsonObject& settings);

 private:
  void volumeChanged();
  void showVolumeChoice();
  void showFieldChoice();
  void resetToCurrent();  // Custom, based on the context's function, its own window, scale 1
  void setShow(bool on);
  void showState();
  void applyTransfer();
  [[nodiscard]] mfr::TransferFunction composed() const;
  [[nodiscard]] double opacityScale() const;
  void showScaleValue();
  void showFunction();  // the preview strip, the editor and its histogram, the point's fields
  void showPreview();
  void showEditor();
  void showSelectedPoint();
  void applyEditor();  // the editor's points as Custom's
  void editSelectedPoint();
  void showStep();
  void stepFromSlider(int position);
  void showInfo();
  void showIsosurfaces();
  void applyIsosurfaces();

  ViewerContext& context_;
  QComboBox* volumeChoice_ = nullptr;
  QWidget* volumeRow_ = nullptr;
  QComboBox* fieldChoice_ = nullptr;  // the file's arrays or grids, when it has several
  QWidget* fieldRow_ = nullptr;
  QLabel* fieldNote_ = nullptr;  // a field being read, or why it could not be
  QCheckBox* show_ = nullptr;
  QLabel* note_ = nullptr;
  QComboBox* preset_ = nullptr;
  QDoubleSpinBox* windowMin_ = nullptr;
  QDoubleSpinBox* windowMax_ = nullptr;
  QSlider* opacity_ = nullptr;
  std::optional<double> exactScale_;  // a loaded opacity_scale, kept exact while the slider is at its step
  QCheckBox* shade_ = nullptr;
  QLabel* opacityValue_ = nullptr;
  QLabel* preview_ = nullptr;
  TransferFunctionEditor* editor_ = nullptr;
  QDoubleSpinBox* pointValue_ = nullptr;
  QDoubleSpinBox* pointOpacity_ = nullptr;
  QDoubleSpinBox* pointRed_ = nullptr;
  QDoubleSpinBox* pointGreen_ = nullptr;
  QDoubleSpinBox* pointBlue_ = nullptr;
  QPushButton* pointColor_ = nullptr;
  QWidget* pointFields_ = nullptr;
  QLabel* error_ = nullptr;
  QSlider* stepSlider_ = nullptr;
  QDoubleSpinBox* step_ = nullptr;
  QLabel* info_ = nullptr;
  QLineEdit* isoValues_ = nullptr;
  QDoubleSpinBox* isoOpacity_ = nullptr;
  QLabel* isoNote_ = nullptr;
  QString isoError_;  // why the last Apply was refused
  QWidget* controls_ = nullptr;

  QString sceneKey_;      // the volume the panel was set up for
  QString histogramKey_;  // the volume and range of the editor's histogram
  // The window, exact (the spin boxes show it rounded to their decimals): the function's own range
  // after resetToCurrent, so Custom applies it unchanged and sessions restore it to the bit.
  double windowLow_ = 0.0;
  double windowHigh_ = 1.0;
  mfr::TransferFunction base_;     // Custom's points (over their own range) and the unit distance at scale 1
  mfr::TransferFunction applied_;  // what the panel last set (another function: an edit from elsewhere)
  // The panel's state of each volume it was set up for (by sceneKey_), so that choosing another
  // volume and back finds the preset, window and opacity scale as they were: the scaled function
  // became the base at 1× and the next scale compounded it (a bug hunt). Kept for one scene.
  struct VolumeState {
    mfr::TransferFunction base, applied;
    QString preset;
    double windowLow = 0.0, windowHigh = 0.0;
    int opacityPosition = 0;
    std::optional<double> exactScale;
  };
  QMap<QString, VolumeState> volumeStates_;
  quint64 volumeStatesScene_ = 0;  // ViewerContext::sceneSerial they belong to
  QString previousOperation_;      // replaced by "volume" when the switch went on, else empty
  QString previousMethod_;         // replaced by kVolumeMethod when the switch went on, else empty
};
