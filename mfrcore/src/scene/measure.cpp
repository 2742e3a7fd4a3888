// Area and enclosed volume by the divergence theorem over the triangles (the volume of each
// triangle's cone to the origin, signed), and the edge topology that says whether that volume means
// anything.
#include "mfr/scene/measure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>
#include <vector>

namespace mfr {

namespace {

using Cell = glm::i64vec3;

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    return static_cast<std::size_t>(c.x * 73856093LL ^ c.y * 19349663LL ^ c.z * 83492791LL);
  }
};

// One id per group of positions closer than `tolerance` to a first one: a grid of cells that size,
// each point compared with the points already in its cell and the 26 around it.
std::vector<std::uint32_t> weldPositions(const std::vector<glm::vec3>& positions, double tolerance) {
  std::vector<std::uint32_t> ids(positions.size());
  std::vector<glm::dvec3> representatives;
  std::unordered_map<Cell, std::vector<std::uint32_t>, CellHash> cells;
  cells.reserve(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const glm::dvec3 p(positions[i]);
    const Cell c(glm::floor(p / tolerance));
    std::uint32_t found = UINT32_MAX;
    for (int dz = -1; dz <= 1 && found == UINT32_MAX; ++dz)
      for (int dy = -1; dy <= 1 && found == UINT32_MAX; ++dy)
        for (int dx = -1; dx <= 1 && found == UINT32_MAX; ++dx) {
          const auto it = cells.find(c + Cell(dx, dy, dz));
          if (it == cells.end()) continue;
          for (const std::uint32_t id : it->second)
            if (glm::distance(representatives[id], p) <= tolerance) {
              found = id;
              break;
            }
        }
    if (found == UINT32_MAX) {
      found = static_cast<std::uint32_t>(representatives.size());
      representatives.push_back(p);
      cells[c].push_back(found);
    }
    ids[i] = found;
  }
  return ids;
}

// Boundary, non-manifold and wrongly wound edges of the triangles over vertex ids `id`.
struct Topology {
  std::size_t boundary = 0, nonManifold = 0, flips = 0;
  [[nodiscard]] std::size_t faults() const { return boundary + nonManifold + flips; }
};

Topology topology(const std::vector<std::uint32_t>& indices, const std::vector<std::uint32_t>& id) {
  struct EdgeUse {
    int count = 0;
    int forward = 0;  // +1 for a → b (a < b), −1 for b → a
  };
  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(indices.size());
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const std::uint32_t v[3] = {id[indices[t]], id[indices[t + 1]], id[indices[t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;  // degenerate: no edge
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t a = v[c], b = v[(c + 1) % 3];
      EdgeUse& e = edges[(static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b)];
      ++e.count;
      e.forward += a < b ? 1 : -1;
    }
  }
  Topology result;
  for (const auto& [key, e] : edges) {
    result.boundary += e.count == 1;
    result.nonManifold += e.count > 2;
    result.flips += e.count == 2 && e.forward != 0;
  }
  return result;
}

}  // namespace

SurfaceMeasures measureSurface(const Mesh& mesh, const glm::dmat4& transform) {
  SurfaceMeasures m;
  // The tetrahedra are summed about the part's centre, not the world's origin: about the origin a
  // part far from it has large terms that cancel, and a 2-unit box at 10⁸ measured 4·10⁸ (a bug hunt).
  const Bounds box = mesh.bounds();
  const glm::dvec3 centre =
      box.valid() ? glm::dvec3(transform * glm::dvec4(0.5 * (box.min + box.max), 1.0)) : glm::dvec3(0.0);
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    glm::dvec3 w[3];
    for (int c = 0; c < 3; ++c)
      w[c] = glm::dvec3(transform *
                        glm::dvec4(glm::dvec3(mesh.positions[mesh.indices[t + static_cast<std::size_t>(c)]]), 1.0)) -
             centre;
    m.area += 0.5 * glm::length(glm::cross(w[1] - w[0], w[2] - w[0]));
    m.volume += glm::dot(w[0], glm::cross(w[1], w[2])) / 6.0;
  }
  // A mirroring placement reverses the winding in the world; the sign stays the part's own.
  if (glm::determinant(glm::dmat3(transform)) < 0.0) m.volume = -m.volume;

  // The edges between the mesh's own vertices — an isosurface's or a welded file's, where distinct
  // vertices may coincide on purpose (a surface through a sample) —, or, when that leaves more edges
  // unmatched, between positions that coincide or are one up to rounding (within 10⁻⁶ of the mesh's diagonal: vertices
  // split by normals or colours, as STL files have, a tessellation's seam rounded apart).
  std::vector<std::uint32_t> own(mesh.positions.size());
  for (std::size_t i = 0; i < own.size(); ++i) own[i] = static_cast<std::uint32_t>(i);
  Topology best = topology(mesh.indices, own);
  // Positions that coincide are welded first (a section cap's vertices are copies of its cut line's):
  // welded at 10⁻⁶ alone, the cut of a part with a ring of vertices on the plane (sectionMesh cuts
  // such a part 10⁻⁶ of its size further in) lost the slivers beside the ring, and a capped sphere
  // cut through a meridian read "not closed (24 boundary edges)" (hunt 32).
  if (best.faults() > 0) {
    const Bounds bounds = mesh.bounds();
    const double diagonal = bounds.valid() ? glm::length(bounds.max - bounds.min) : 0.0;
    for (const double tolerance : {1e-9, 1e-6}) {
      if (best.faults() == 0) break;
      const Topology welded =
          topology(mesh.indices, weldPositions(mesh.positions, diagonal > 0.0 ? tolerance * diagonal : 1e-30));
      if (welded.faults() < best.faults()) best = welded;
    }
  }
  m.boundaryEdges = best.boundary;
  m.nonManifoldEdges = best.nonManifold;
  m.orientationFlips = best.flips;
  return m;
}

std::string describeSurface(const SurfaceMeasures& m) {
  std::ostringstream text;  // default stream formatting: six significant digits
  text << "area " << m.area;
  if (!(m.area > 0.0)) {
    text << ": no surface (every triangle is degenerate)";  // "closed, volume 0" said nothing true
  } else if (m.closed()) {
    text << ", closed, volume " << m.volume << (m.volume < 0.0 ? " (inside out)" : "");
  } else {
    text << ", not closed (" << m.boundaryEdges << " boundary edges";
    if (m.nonManifoldEdges > 0) text << ", " << m.nonManifoldEdges << " non-manifold";
    if (m.orientationFlips > 0) text << ", " << m.orientationFlips << " wound against a neighbour";
    text << "): no enclosed volume";
  }
  return text.str();
}

}  // namespace mfr
