#pragma once
// Isosurfaces of a volume (ParaView's Contour filter): the surface where the volume's samples equal
// a value, extracted by VTK's flying edges and added to the scene as parts of their own, so that
// every method draws them — nested translucent isosurfaces are what deep fragment lists are made of.
#include <cstddef>
#include <string>
#include <vector>

#include "mfr/scene/mesh.hpp"
#include "mfr/scene/scene.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr {

// The most isosurfaces one request adds (each is a full pass over the grid and a part to draw).
inline constexpr std::size_t kMaxContourValues = 16;

// The isosurface of `volume` at `value`, in the volume's object space (grid point (i, j, k) at
// origin + (i, j, k)·spacing; the part's transform is the volume's). Its vertices lie on grid edges
// where the edge's two samples, interpolated linearly, equal `value` — so the volume's trilinear
// sample (VolumeGrid::sample) is `value` at every vertex. Normals are the samples' gradient, pointing
// towards lower values (out of the region above `value`: bone into soft tissue, skin into air), and
// each triangle winds counter-clockwise seen from the side its normals point to — in object space, as
// every part's (a mirroring transform reverses its facing in the world; CSG and section caps allow
// for that, as for any mirrored part). An isosurface that
// reaches the grid's boundary is open there. Empty when the samples do not cross `value`.
Mesh contourVolume(const Volume& volume, double value);

// The isosurface parts of a request: one per value, in the given order.
struct ContourRequest {
  std::size_t volume = 0;      // index into Scene::volumes
  std::vector<double> values;  // 1 ≤ count ≤ kMaxContourValues, each strictly inside the grid's range
  float opacity = 0.5f;        // of every part made
};

// Adds one part per value to scene.objects, named "<volume name> = <value>" (the value as %g), with
// the volume's transform, coloured by its value through the cool-warm map (ParaView colours contours
// by their value) — over [lowest, highest] of several values, so that they differ most (the lowest
// blue, the highest red); over the grid's range for one — with request.opacity; then addVolumeFields, so that
// they too can be coloured by any volume of the scene ("@NAME"). Returns the new parts' indices.
// Throws mfr::Error(what, reason), leaving the scene unchanged, for: no such volume, no value, more
// than kMaxContourValues, a non-finite value, a value outside the open interval of the grid's range
// (it gives no surface), an opacity outside [0, 1].
std::vector<std::size_t> addContours(Scene& scene, const ContourRequest& request, const std::string& what);

// The values addContours maps to the cool-warm map's ends: [lowest, highest] of several values, the
// grid's range for one (what a legend of the isosurfaces shows: drawColorLegend with their values
// as ticks).
glm::dvec2 contourColorRange(const std::vector<double>& values, const glm::dvec2& gridRange);

// "<volume name> = <value>": the name addContours gives the part.
std::string contourPartName(const std::string& volumeName, double value);

}  // namespace mfr
