#pragma once
// Cameras: look-at frame plus perspective or orthographic projection. Matrices follow OpenGL
// conventions (right-handed eye space looking down -Z, NDC depth in [-1, 1], window depth in
// [0, 1]). The oracle uses the same matrices, in double precision, to build its rays.
#include <glm/glm.hpp>
#include <optional>
#include <string>

#include "mfr/scene/mesh.hpp"

namespace mfr {

enum class Projection { Perspective, Orthographic };

struct Camera {
  glm::dvec3 eye{0.0, 0.0, 5.0};
  glm::dvec3 target{0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  Projection projection = Projection::Perspective;
  // Both span the image's shorter side (its height when it is landscape or square, its width when
  // it is portrait), so the fit-all view frames the scene whatever the image's shape.
  double fovyDegrees = 40.0;  // perspective
  double orthoHeight = 2.0;   // orthographic: world extent of the view
  double nearPlane = 0.1;
  double farPlane = 100.0;
  // Near and far were given (a scene file's view with "near"/"far", or a session that saved such
  // a view): the viewer keeps them instead of fitting them to what is drawn, as mfr render does.
  // Fitting to valid bounds (fittedTo, fitDepthRange) clears it.
  bool depthRangeGiven = false;

  [[nodiscard]] glm::dmat4 viewMatrix() const;
  [[nodiscard]] glm::dmat4 projectionMatrix(double aspect) const;
  // Window depth d in [0,1] → eye depth (distance along the view axis, > 0 in front of the eye):
  // z = -(a·ndc + b)/(c·ndc + e) with ndc = 2d - 1; returns (a, b, c, e), from the inverse
  // projection (the z row does not depend on the aspect ratio or on x, y).
  [[nodiscard]] glm::dvec4 depthToEye() const;
  // Unit vector from eye towards target: also the headlight direction.
  [[nodiscard]] glm::dvec3 forward() const;

  // Keeps the direction (eye → target) and up, moves the camera so the bounding sphere of b
  // fills the view, and sets near/far to enclose it.
  // radius > 0 gives a tighter sphere around b's centre than b's half-diagonal (Scene computes
  // it from the vertices).
  // Why eye, target and up give no view, or nothing: {key ("" or "up"), reason}. Scene files'
  // views and sessions' cameras are checked with it, so neither reaches a renderer's "projection
  // is singular" naming neither the file nor the key.
  struct Defect {
    std::string key;
    std::string reason;
  };
  [[nodiscard]] std::optional<Defect> frameDefect() const;
  // The view-projection (aspect 1) has no finite inverse: near 1e-30 with far 1e30, say.
  [[nodiscard]] bool projectionSingular() const;

  // A given near and far (a scene file's view) whose 32-bit window depth cannot tell apart
  // fragments a thousandth of the drawn bounds' diagonal apart at their far side: the GPU methods,
  // which keep window depths as floats, may misorder such fragments (near 1e-5 with far 6 resolved
  // 0.2 units, and A-buffers drew 262 of 6,912 pixels up to 35/255 off; a bug hunt). Fitted planes
  // (far/near ≤ 10⁴) get none. The note's text, or nullopt.
  [[nodiscard]] std::optional<std::string> depthPrecisionNote(const Bounds& drawn) const;

  [[nodiscard]] Camera fittedTo(const Bounds& b, double radius = 0.0) const;
  // Recomputes only near/far so the sphere lies between them (camera position unchanged); the
  // planes are fitted, not given, afterwards.
  void fitDepthRange(const Bounds& b, double radius = 0.0);
};

}  // namespace mfr
