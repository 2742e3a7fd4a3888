#pragma once
// Section views: a scene cut by its section plane (Scene::section), as geometry. Surfaces are
// clipped triangle by triangle (winding, normals and colours kept, cut edges shared between the
// triangles that share an edge); the cross-section of every closed surface is triangulated by
// CGAL's constrained Delaunay triangulation into a cap with the plane's normal, so a cut solid stays
// a closed, outward-oriented solid (CSG and the solid-aware operations still see solids).
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/mesh.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

// What cutting one mesh did.
enum class SectionOutcome {
  kKept,     // entirely on the kept side: unchanged
  kRemoved,  // entirely on the cut-away side
  kCut,      // cut, no cap (caps off, the cut line is not closed, or the cap failed its area check)
  kCapped,   // cut and capped
};

struct SectionedMesh {
  Mesh mesh;  // empty unless kCut or kCapped
  SectionOutcome outcome = SectionOutcome::kKept;
  std::size_t capTriangles = 0;  // the last capTriangles triangles of mesh are the cap
  bool closed = false;           // the cut line formed closed loops (tested only when caps were asked for)
  // When caps were asked for and none was made: the cut line, segments exit → entry (indices into
  // mesh) in the surface's winding. sectionedScene joins those of objects that are one solid together.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> cutLine;
  // With cutLine: where its chains end after welding (a vertex of mesh, and whether more segments
  // enter it than leave), so that sectionedScene can join them to other parts' without welding again.
  std::vector<std::pair<std::uint32_t, bool>> openEnds;
};

// Cuts `mesh` by the plane dot(plane.xyz, p) + plane.w >= 0 (kept side, object space). A mesh
// that only touches the plane (vertices within 1e-9 of its size of it, none beyond) is kept or
// removed whole; one cut through with vertices on the plane is cut 1e-6 of its size further in,
// where no vertex is, so faces lying in the plane never enter the cut line. With `caps`, the cut
// line — the segments where triangles cross the plane, repeats counted once, a segment and its
// reverse cancelled, chains ending within 1e-3 of the bounding box's diagonal of another's start
// joined — must form closed loops (the surface is closed where the plane cuts it; holes elsewhere do
// not matter); the loops are filled by the nonzero winding rule (overlapping loops of a
// self-intersecting surface once, a cavity wound the other way not at all; where the line crosses
// itself the cap gets a vertex), and the cap is kept only if its faces' areas times their winding
// numbers add up to the area the loops enclose (0.1 %): a failed triangulation is dropped, never
// drawn. Caps get the normal -plane.xyz (outward) and, when the mesh has vertex colours, the
// colours of the cut.
SectionedMesh sectionMesh(const Mesh& mesh, const glm::dvec4& plane, bool caps);

// A section plane as `mfr render --section` and `mfrview --section` take it: AXIS=VALUE (x, y, z,
// -x, -y, -z: the plane across that axis at VALUE, keeping the side the axis points to) or six
// numbers px,py,pz,nx,ny,nz (a point and the kept side's normal), optionally followed by :nocaps
// and/or :slice. Throws mfr::Error(what, reason) for anything else or a zero normal.
SectionPlane parseSectionPlane(const std::string& text, const std::string& what);

struct SectionReport {
  std::size_t cut = 0;     // objects cut (capped or not)
  std::size_t capped = 0;  // of those, capped (alone or together with the other parts of their solid)
  std::size_t removed = 0;
  std::vector<std::string> open;  // names of objects cut without a cap though caps were asked for
  std::size_t slices = 0;         // volume slices added (SectionPlane::slice)
  // Per object of the sectioned scene, the slices added last included (kKept, no cap): what the
  // plane did to it (kKept for hidden or empty ones too), and the world area of its cap — the part's cross-section,
  // FreeCAD's section area —, 0 without one. A solid split over parts and capped jointly has the whole cap on the part
  // that holds it.
  std::vector<SectionOutcome> outcomes;
  std::vector<double> capAreas;
  [[nodiscard]] double totalCapArea() const;
};

// The plane's cross-section of a volume's box (grid points [0, dims − 1], as Volume::bounds): a
// convex polygon in world space wound counter-clockwise seen from the cut-away side (its normal is
// −n, as a cap's), empty when the plane misses the box or only touches it. plane: (n, d), kept where
// dot(n, p) + d >= 0 (sectionPlaneEquation).
std::vector<glm::dvec3> volumeSlicePolygon(const Volume& volume, const glm::dvec4& plane);

// The scene with its section applied to the surfaces: cut objects get new meshes, objects entirely
// on the cut-away side become invisible, and sectionCut is set. Objects that are open along the cut
// but whose cut lines join into closed loops together (one solid split over several parts: a glTF
// mesh with a primitive per material) get one cap, on the part with the most of the joint cut line;
// both then count as capped. The section itself stays: the renderers crop the volume's march with
// it. With SectionPlane::slice each volume gets a part "NAME slice" (NAME as volumeFieldName
// without its "@"): its volumeSlicePolygon, moved (v + 1)·10⁻⁴ of the largest volume box's
// diagonal into the kept side — caps in the plane lie in front of it, and where volumes overlap the
// first one's slice is in front, without z-fighting — coloured by the volume at each point (grayscale
// over the transfer function's range), opaque. A scene without a section, or already cut, is returned unchanged. Throws
// mfr::Error("section plane", …) when nothing visible is left.
Scene sectionedScene(const Scene& scene, SectionReport* report = nullptr);

// What a section could not do as asked, one line each, for mfr render and mfrview's scripted runs
// to print as notes: parts cut without a cap though caps were asked for, a slice the plane misses.
std::vector<std::string> sectionNotes(const SectionPlane& plane, const SectionReport& report);

// What mfr info and the viewer's scene tree add after a part's measures (describeSurface) when a
// section cut it: "; cut, cross-section area 4" (capped; six significant digits), "; cut, capped
// with another part" (capped jointly, the cap on another part), "; cut" (no cap); "" when kept. A
// removed part has no measures: "removed by the section" is the whole line.
std::string describeCut(SectionOutcome outcome, double capArea);

// The plane of a section as (n, d), n unit length, kept where dot(n, p) + d >= 0 (world space).
glm::dvec4 sectionPlaneEquation(const SectionPlane& plane);

}  // namespace mfr
