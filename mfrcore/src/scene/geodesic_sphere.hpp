#pragma once
// The geodesic sphere: an icosahedron whose faces are cut into a triangular grid and pushed out
// onto the unit sphere. Its triangles are nearly equilateral everywhere (edge ratio within a
// triangle at most 1.18), unlike a latitude–longitude sphere's slivers at the poles. Private to
// mfrcore: atoms drawn as spheres and a lone atom's molecular surface share it.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mfr {

struct UnitSphere {
  std::vector<glm::dvec3> vertices;  // unit length, each shared by all its triangles
  std::vector<std::uint32_t> indices;
};

// Each of the icosahedron's 20 faces cut into frequency² triangles (frequency ≥ 1), every vertex
// projected onto the unit sphere; triangles counter-clockwise seen from outside.
// 10·frequency² + 2 vertices, 20·frequency² triangles. For an even frequency the six points
// (±1, 0, 0), (0, ±1, 0), (0, 0, ±1) are vertices (midpoints of the icosahedron's edges along the
// axes), so a sphere's bounding box is its centre ± radius. Frequency 2^l gives the same
// triangle count as l rounds of midpoint subdivision.
UnitSphere geodesicSphere(int frequency);

}  // namespace mfr
