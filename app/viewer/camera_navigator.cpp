#include "camera_navigator.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>

namespace navigation {
namespace {

struct Frame {
  glm::dvec3 forward, right, up;
  double distance;
};

Frame frameOf(const mfr::Camera& c) {
  Frame f;
  f.forward = c.forward();
  f.right = glm::cross(f.forward, c.up);
  if (glm::length(f.right) < 1e-12) f.right = glm::cross(f.forward, glm::dvec3(0, 0, 1));
  f.right = glm::normalize(f.right);
  f.up = glm::cross(f.right, f.forward);
  f.distance = std::max(glm::length(c.target - c.eye), 1e-9);
  return f;
}

// World units per pixel on the plane through the target, perpendicular to the view direction (the
// field of view spans the view's shorter side, mfr::Camera).
double worldPerPixel(const mfr::Camera& c, const Frame& f, QSize view) {
  const double height = std::max(1, std::min(view.width(), view.height()));
  if (c.projection == mfr::Projection::Orthographic) return c.orthoHeight / height;
  return 2.0 * f.distance * std::tan(glm::radians(c.fovyDegrees) * 0.5) / height;
}

}  // namespace

mfr::Camera orbit(const mfr::Camera& camera, QPointF delta, QSize view) {
  const double len = std::hypot(delta.x(), delta.y());
  if (len == 0.0) return camera;
  const Frame f = frameOf(camera);
  // Dragging right turns the scene right: the eye moves left around the target.
  const glm::dvec3 axis = glm::normalize(f.up * delta.x() + f.right * delta.y());
  const double angle = -glm::pi<double>() * len / std::max(1, view.height());
  const glm::dquat rotation = glm::angleAxis(angle, axis);
  mfr::Camera c = camera;
  c.eye = c.target + rotation * (camera.eye - camera.target);
  c.up = rotation * f.up;
  c.depthRangeGiven = false;
  return c;
}

mfr::Camera pan(const mfr::Camera& camera, QPointF delta, QSize view) {
  const Frame f = frameOf(camera);
  const double s = worldPerPixel(camera, f, view);
  const glm::dvec3 shift = (-f.right * delta.x() + f.up * delta.y()) * s;
  mfr::Camera c = camera;
  c.eye += shift;
  c.target += shift;
  c.depthRangeGiven = false;
  return c;
}

mfr::Camera zoomAt(const mfr::Camera& camera, QPointF cursor, QSize view, double steps) {
  const double factor = std::pow(0.85, steps);
  const Frame f = frameOf(camera);
  const double s = worldPerPixel(camera, f, view);
  // Target-plane point under the cursor (widget y grows downwards).
  const glm::dvec3 point = camera.target + f.right * ((cursor.x() - 0.5 * view.width()) * s) +
                           f.up * ((0.5 * view.height() - cursor.y()) * s);
  mfr::Camera c = camera;
  c.target = point + (camera.target - point) * factor;
  if (camera.projection == mfr::Projection::Orthographic) {
    c.orthoHeight = camera.orthoHeight * factor;
    c.eye = c.target - f.forward * f.distance;
  } else {
    c.eye = point + (camera.eye - point) * factor;
  }
  c.depthRangeGiven = false;
  return c;
}

mfr::Camera toggledProjection(const mfr::Camera& camera) {
  mfr::Camera c = camera;
  const Frame f = frameOf(camera);
  if (camera.projection == mfr::Projection::Perspective) {
    c.projection = mfr::Projection::Orthographic;
    c.orthoHeight = 2.0 * f.distance * std::tan(glm::radians(camera.fovyDegrees) * 0.5);
  } else {
    c.projection = mfr::Projection::Perspective;
    // Keep the framing: move the eye so the target plane spans orthoHeight again.
    const double distance = 0.5 * camera.orthoHeight / std::tan(glm::radians(camera.fovyDegrees) * 0.5);
    c.eye = camera.target - f.forward * distance;
  }
  c.depthRangeGiven = false;
  return c;
}

QString standardViewName(StandardView view) {
  switch (view) {
    case StandardView::Front:
      return QStringLiteral("Front");
    case StandardView::Back:
      return QStringLiteral("Back");
    case StandardView::Left:
      return QStringLiteral("Left");
    case StandardView::Right:
      return QStringLiteral("Right");
    case StandardView::Top:
      return QStringLiteral("Top");
    case StandardView::Bottom:
      return QStringLiteral("Bottom");
    case StandardView::Iso:
      return QStringLiteral("Isometric");
  }
  return {};
}

mfr::Camera standardView(StandardView view, const mfr::Scene& scene, const mfr::Camera& current) {
  glm::dvec3 towardsEye{0, 0, 1}, up{0, 1, 0};  // front: looking down −Z, +Y up
  switch (view) {
    case StandardView::Front:
      break;
    case StandardView::Back:
      towardsEye = {0, 0, -1};
      break;
    case StandardView::Left:
      towardsEye = {-1, 0, 0};
      break;
    case StandardView::Right:
      towardsEye = {1, 0, 0};
      break;
    case StandardView::Top:
      towardsEye = {0, 1, 0};
      up = {0, 0, -1};
      break;
    case StandardView::Bottom:
      towardsEye = {0, -1, 0};
      up = {0, 0, 1};
      break;
    case StandardView::Iso:
      towardsEye = glm::normalize(glm::dvec3(1, 1, 1));
      break;
  }
  mfr::Camera base = current;
  base.up = up;
  if (!scene.bounds().valid()) {
    // Nothing visible to frame: turn about the current target at the current distance (the fit
    // of nothing put the eye 1 unit from the origin, inside @sample's shell once a part was shown
    // again: a bug hunt).
    base.eye = current.target + towardsEye * glm::length(current.eye - current.target);
    base.depthRangeGiven = false;
    return base;
  }
  base.target = glm::dvec3(0.0);
  base.eye = towardsEye;
  return scene.fit(base);
}

}  // namespace navigation
