#pragma once
// A unit vector perpendicular to a direction, for building a frame around an axis (tubes,
// circles, a cartoon's first ring). Private to mfrcore.
#include <cmath>

#include <glm/glm.hpp>

namespace mfr {

// Unit and perpendicular to `axis` (any length > 0): the cross product with the x axis, or with
// the y axis when `axis` runs nearly along x.
inline glm::dvec3 anyPerpendicular(const glm::dvec3& axis) {
  const glm::dvec3 unit = glm::normalize(axis);
  const glm::dvec3 helper = std::abs(unit.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(unit, helper));
}

}  // namespace mfr
