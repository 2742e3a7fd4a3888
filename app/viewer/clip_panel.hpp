#pragma once
// The Clip dock: a box that cuts the scene open (mfr::Scene::clipBox). Only what lies inside it is
// drawn — by every method and the oracle, surfaces cut along its faces and the volume cropped — so
// the inside of a dense assembly or a CT shows without hiding parts. Per axis two sliders set the
// box's faces as fractions of the scene's bounds (as loaded, unclipped), with the world values
// beside them; Reset gives back the whole bounds. A scene file's own "clip" shows as loaded, and
// sessions save the box.
#include <QWidget>

#include <array>
#include <optional>

#include "mfr/scene/mesh.hpp"

class QCheckBox;
class QLabel;
class QPushButton;
class QSlider;
class ViewerModel;

class ClipPanel final : public QWidget {
  Q_OBJECT

 public:
  static constexpr int kSteps = 1000;  // slider positions over the bounds

  explicit ClipPanel(ViewerModel& model, QWidget* parent = nullptr);
  // The box the sliders give over bounds (position p ↦ min + p/kSteps · extent on each axis).
  [[nodiscard]] static mfr::Bounds boxFromPositions(const mfr::Bounds& bounds, const std::array<int, 3>& low,
                                                    const std::array<int, 3>& high);

 private:
  void showModel();  // controls from the model's clip box
  void apply();      // the model's clip box from the controls

  ViewerModel& model_;
  QCheckBox* enabled_ = nullptr;
  std::array<QSlider*, 3> low_{};
  std::array<QSlider*, 3> high_{};
  std::array<QLabel*, 3> values_{};
  QPushButton* reset_ = nullptr;
  bool showing_ = false;  // controls being set from the model: no apply()
};
