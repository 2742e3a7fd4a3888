#pragma once
// The Clip dock: a box that cuts the scene open (mfr::Scene::clipBox). Only what lies inside it is
// drawn — by every method and the oracle, surfaces cut along its faces and the volume cropped — so
// the inside of a dense assembly or a CT shows without hiding parts. Per axis two sliders set the
// box's faces as fractions of the scene's bounds (as loaded, unclipped), with the world values
// beside them; Reset gives back the whole bounds. A scene file's own "clip" shows as loaded, and
// sessions save the box.
// Below it, the section plane (mfr::Scene::section): perpendicular to X, Y or Z (or a scene file's
// own normal, "Custom"), moved by a slider across the scene's extent along that normal, keeping the
// side the normal points to unless flipped; closed parts are capped unless Caps is off, and with
// Volume slice each volume shows its samples on the plane (SectionPlane::slice). "Align to
// view" puts it through the view's target, facing away from the eye (the near half is cut away).
// A line below says how many cut parts got a cap and names those that did not (open along the cut).
#include <QWidget>

#include <array>
#include <functional>
#include <optional>

#include "mfr/scene/mesh.hpp"
#include "mfr/scene/scene.hpp"

class QCheckBox;
class QComboBox;
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
  // The plane perpendicular to unit `axis` at slider `position` of the bounds' extent along it,
  // keeping the side `axis` points to (the other with `flip`).
  [[nodiscard]] static mfr::SectionPlane sectionFromPosition(const mfr::Bounds& bounds, const glm::dvec3& axis,
                                                             int position, bool flip, bool caps, bool slice = false);

 private:
  void showModel();  // controls from the model's clip box
  // The model's clip box from the sliders: all faces (axis −1), or only `axis`'s low, high or both
  // faces (the others keep the model's).
  enum class Face { Low, High, Both };
  void applyBox(int axis, Face face);
  void placeSection();  // the model's plane from the axis, offset, side and flags shown
  // The model's plane with one property changed, the rest (its point) as it is.
  void editSection(const std::function<void(mfr::SectionPlane&)>& edit);

  ViewerModel& model_;
  QCheckBox* enabled_ = nullptr;
  std::array<QSlider*, 3> low_{};
  std::array<QSlider*, 3> high_{};
  std::array<QLabel*, 3> values_{};
  QPushButton* reset_ = nullptr;
  QCheckBox* sectionEnabled_ = nullptr;
  QComboBox* sectionAxis_ = nullptr;  // X, Y, Z, and "Custom" while a file's own normal is shown
  QSlider* sectionOffset_ = nullptr;
  QCheckBox* sectionFlip_ = nullptr;
  QCheckBox* sectionCaps_ = nullptr;
  QCheckBox* sectionSlice_ = nullptr;  // SectionPlane::slice (a scene with a volume)
  QLabel* sectionValue_ = nullptr;
  QPushButton* sectionAlign_ = nullptr;
  QLabel* sectionReport_ = nullptr;         // how many cut parts are capped; the others' names in its tooltip
  glm::dvec3 customNormal_{0.0, 0.0, 1.0};  // unit; the "Custom" entry's axis
  bool showing_ = false;                    // controls being set from the model: no apply()
};
