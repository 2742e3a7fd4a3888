#include "mfr/scene/camera.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace mfr {

glm::dmat4 Camera::viewMatrix() const {
  return glm::lookAt(eye, target, up);
}

glm::dmat4 Camera::projectionMatrix(double aspect) const {
  // The field of view (orthoHeight) spans the image's shorter side: a portrait image shows as much
  // across as a landscape one shows top to bottom, so what fits one fits the other.
  const double shorter = std::min(aspect, 1.0);
  if (projection == Projection::Orthographic) {
    const double h = 0.5 * orthoHeight / shorter;
    const double w = h * aspect;
    return glm::ortho(-w, w, -h, h, nearPlane, farPlane);
  }
  const double fovy = 2.0 * std::atan(std::tan(0.5 * glm::radians(fovyDegrees)) / shorter);
  return glm::perspective(fovy, aspect, nearPlane, farPlane);
}

glm::dvec4 Camera::depthToEye() const {
  const glm::dmat4 inverse = glm::inverse(projectionMatrix(1.0));
  return {inverse[2][2], inverse[3][2], inverse[2][3], inverse[3][3]};
}

std::optional<Camera::Defect> Camera::frameDefect() const {
  if (glm::length(eye - target) == 0.0) return Defect{"", "eye and target coincide"};
  // Beyond ~1e154 apart the view direction cannot be normalised (it read as "up: parallel").
  if (!std::isfinite(glm::length(eye - target)))
    return Defect{"", "eye and target too far apart to give a view direction (under 1e150)"};
  if (!(glm::length(up) > 0.0)) return Defect{"up", "must not be zero"};
  if (!std::isfinite(glm::length(up))) return Defect{"up", "too long to normalise (under 1e150)"};
  if (!(glm::length(glm::cross(forward(), glm::normalize(up))) >= 1e-9))
    return Defect{"up", "parallel to the view direction"};
  return std::nullopt;
}

bool Camera::projectionSingular() const {
  const glm::dmat4 inverse = glm::inverse(projectionMatrix(1.0) * viewMatrix());
  const double* m = glm::value_ptr(inverse);
  return !std::all_of(m, m + 16, [](double x) { return std::isfinite(x); });
}

glm::dvec3 Camera::forward() const {
  const glm::dvec3 d = target - eye;
  const double len = glm::length(d);
  return len > 0.0 ? d / len : glm::dvec3(0.0, 0.0, -1.0);
}

Camera Camera::fittedTo(const Bounds& b, double radius) const {
  Camera c = *this;
  if (!b.valid()) return c;
  const glm::dvec3 centre = b.center();
  // No absolute floor: a scene 1e-11 across was framed as if 1e-9 (a blank image).
  const double given = radius > 0.0 ? radius : b.radius();
  const double r = given > 0.0 && std::isfinite(given) ? given : 1.0;
  const glm::dvec3 dir = forward();
  // Distance at which a sphere of radius r fills the vertical field of view, with a small margin.
  const double halfFov = glm::radians(std::clamp(fovyDegrees, 1.0, 170.0)) * 0.5;
  const double dist = 1.05 * r / std::sin(halfFov);
  c.target = centre;
  c.eye = centre - dir * dist;
  c.orthoHeight = 2.1 * r;
  c.fitDepthRange(b, r);
  return c;
}

std::optional<std::string> Camera::depthPrecisionNote(const Bounds& drawn) const {
  if (!depthRangeGiven || !drawn.valid()) return std::nullopt;
  const double n = nearPlane, f = farPlane;
  // The farthest drawn depth the planes keep: where window depth is coarsest.
  double zMax = n;
  for (int corner = 0; corner < 8; ++corner) {
    zMax = std::max(zMax, glm::dot(drawn.corner(corner) - eye, forward()));
  }
  zMax = std::clamp(zMax, n, f);
  // A float's spacing in [0.5, 1), where window depth lies but near the near plane, times dz/dd.
  const double spacing = std::ldexp(1.0, -24);
  const double resolution =
      projection == Projection::Perspective ? spacing * (f - n) * zMax * zMax / (f * n) : spacing * (f - n);
  const double diagonal = glm::length(drawn.max - drawn.min);
  if (!(resolution > 1e-3 * diagonal)) return std::nullopt;
  std::ostringstream text;
  text << std::setprecision(3) << "near " << n << " and far " << f << " resolve depths only " << resolution
       << " apart at the far side of what is drawn (32-bit window depth): the GPU methods may misorder fragments "
          "closer than that (a larger near plane resolves them)";
  return text.str();
}

void Camera::fitDepthRange(const Bounds& b, double radius) {
  if (!b.valid()) return;
  const double given = radius > 0.0 ? radius : b.radius();
  const double r = given > 0.0 && std::isfinite(given) ? given : 1.0;
  const double d = glm::dot(b.center() - eye, forward());
  // Near/far enclose the bounding sphere; near stays positive and not absurdly small, so depth
  // precision stays usable (ratio far/near ≤ 1e4). Far at least the sphere's size beyond the eye
  // (the eye inside the sphere), with no absolute floor.
  farPlane = std::max(d + 1.01 * r, 1.01 * r);
  nearPlane = std::max(d - 1.01 * r, farPlane * 1e-4);
  depthRangeGiven = false;
}

}  // namespace mfr
