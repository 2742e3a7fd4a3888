#pragma once
// Consistent winding and feature-edge vertex normals for indexed triangles: the result of VTK's
// vtkPolyDataNormals with consistency, non-manifold traversal and splitting on (what every mesh
// loader used), computed over an edge map. vtkPolyData's edge-neighbour query scans every cell of
// an edge's first point, so the filter took time quadratic in a vertex's valence: minutes for a
// disc drawn as a fan of 200,000 triangles. Here each step is linear in the mesh size (plus one
// sort of its edges).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mfr {

struct FeatureSplit {
  // 3 per triangle: the input triangles, each either as given or reversed (c, b, a) so that
  // neighbours across an edge run it in opposite directions, with the corners at a feature edge's
  // far side renumbered to copies of their vertex.
  std::vector<std::uint32_t> indices;
  // One per output vertex: the input vertex it is (the first positions.size() are the input's own).
  std::vector<std::uint32_t> source;
  // One per output vertex: the unit sum of the unit normals of its triangles; zero where they
  // cancel or are all degenerate.
  std::vector<glm::vec3> normals;
  std::size_t reversed = 0;  // triangles whose winding was reversed
};

// Winding: from the lowest-numbered triangle not yet reached, a breadth-first wave over shared
// edges (also non-manifold ones) reverses each newly reached triangle that runs a shared edge in
// the same direction as the triangle it was reached from; the seed keeps its winding, as in VTK's
// filter — or, with `majorityWinding` (the loaders), each connected region keeps the winding most
// of its triangles have as given (the seed's in a tie), so that one reversed triangle listed first
// does not turn a whole part inside out.
// Splitting: around each vertex, triangles joined by a manifold edge (two triangles) whose normals
// are less than `featureAngleDegrees` apart form one region; each region after the first (in
// triangle order) gets its own copy of the vertex. Indices must be < positions.size() (the loaders
// check); a last incomplete triangle is ignored; triangles that repeat a vertex have no edge
// between the repeated corners (where VTK's filter does odd things). Throws std::length_error past
// 2^32 − 1 corners or vertices.
[[nodiscard]] FeatureSplit orientAndSplitAtFeatures(const std::vector<glm::dvec3>& positions,
                                                    std::vector<std::uint32_t> indices, double featureAngleDegrees,
                                                    bool majorityWinding = false);

}  // namespace mfr
