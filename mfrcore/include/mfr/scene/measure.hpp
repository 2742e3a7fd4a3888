#pragma once
// A part's surface measured in the world (ParaView's Mass Properties, the volume InVesalius
// reports for a surface, FreeCAD's measurements): area, whether it is closed, and the volume it
// encloses when it is.
#include <cstddef>
#include <string>

#include <glm/glm.hpp>

#include "mfr/scene/mesh.hpp"

namespace mfr {

struct SurfaceMeasures {
  double area = 0.0;                 // world units²
  double volume = 0.0;               // Σ a·(b × c)/6 over the triangles: the enclosed volume of a closed surface
  std::size_t boundaryEdges = 0;     // edges of one triangle only
  std::size_t nonManifoldEdges = 0;  // edges of three or more
  std::size_t orientationFlips = 0;  // edges whose two triangles run along them the same way
  // Closed and consistently wound: then `volume` is the volume it encloses (positive when the
  // triangles wind counter-clockwise seen from outside in the part's own coordinates — a mirroring
  // transform does not turn it inside out —, negative when inside out).
  [[nodiscard]] bool closed() const { return boundaryEdges == 0 && nonManifoldEdges == 0 && orientationFlips == 0; }
};

// The mesh under `transform` (object → world). Edges join the mesh's own vertices or — when that
// leaves more edges unmatched, as in files whose vertices are split by normals or colours, or a
// tessellation's seam rounded apart — positions welded within 10⁻⁶ of the mesh's diagonal; a
// degenerate triangle (two corners at one vertex) adds no edge. Linear in the triangles (hashes).
SurfaceMeasures measureSurface(const Mesh& mesh, const glm::dmat4& transform);

// One line, as mfr info and the viewer's scene tree print it: "area 32, closed, volume 12" (with
// " (inside out)" for a negative volume), or "area 2, not closed (4 boundary edges[, N
// non-manifold][, N wound against a neighbour]): no enclosed volume"; numbers with six significant
// digits.
std::string describeSurface(const SurfaceMeasures& measures);

}  // namespace mfr
