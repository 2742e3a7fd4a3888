#pragma once
// Procedural meshes, closed and consistently oriented (counter-clockwise seen from outside) where
// the shape is closed, so CSG and facing tests can rely on them.
#include <cstdint>
#include <vector>

#include "mfr/scene/mesh.hpp"

namespace mfr {

Mesh makeSphere(double radius, int slices = 48, int stacks = 24);
Mesh makeBox(const glm::dvec3& size);
Mesh makeCylinder(double radius, double height, int slices = 48);  // capped, axis +Y, centred
Mesh makeTorus(double majorRadius, double minorRadius, int majorSegments = 64, int minorSegments = 24);
Mesh makePlane(double width, double height);  // XY plane, normal +Z, one-sided
// Closed tube (capped) of given radius along a polyline (≥ 2 points).
Mesh makeTube(const std::vector<glm::dvec3>& path, double radius, int sides = 12);
// "Hairball": count random smooth tubes tangled inside a sphere of the given radius; same seed,
// same mesh on every machine (own PRNG, no std:: distribution).
Mesh makeHairball(int count, double radius, double tubeRadius, std::uint32_t seed, int segments = 64, int sides = 10);

}  // namespace mfr
