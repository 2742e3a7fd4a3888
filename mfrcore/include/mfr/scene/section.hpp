#pragma once
// Section views: a scene cut by its section plane (Scene::section), as geometry. Surfaces are
// clipped triangle by triangle (winding, normals and colours kept, cut edges shared between the
// triangles that share an edge); the cross-section of every closed surface is triangulated by VTK's
// CGAL's constrained Delaunay triangulation into a cap with the plane's normal, so a cut solid stays a closed, outward
// oriented solid (CSG and the solid-aware operations still see solids).
#include <cstddef>
#include <string>
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
};

// Cuts `mesh` by the plane dot(plane.xyz, p) + plane.w >= 0 (kept side, object space). With `caps`,
// the cut line — the segments where triangles cross the plane, repeats counted once, a segment and
// its reverse cancelled, chains ending within 1e-4 of the bounding box's diagonal of another's start
// joined — must form closed loops (the surface is closed where the plane cuts it; holes elsewhere do not matter);
// the loops are filled, and the cap is kept only if its area equals the area they enclose (0.1 %):
// a failed triangulation is dropped, never drawn. Caps get the normal -plane.xyz (outward) and, when
// the mesh has vertex colours, the colours of the cut.
SectionedMesh sectionMesh(const Mesh& mesh, const glm::dvec4& plane, bool caps);

struct SectionReport {
  std::size_t cut = 0;     // objects cut (capped or not)
  std::size_t capped = 0;  // of those, capped
  std::size_t removed = 0;
  std::vector<std::string> open;  // names of objects cut without a cap though caps were asked for
};

// The scene with its section applied to the surfaces: cut objects get new meshes, objects entirely
// on the cut-away side become invisible, and sectionCut is set (the section itself stays: the
// renderers crop the volume's march with it). A scene without a section, or already cut, is returned
// unchanged. Throws mfr::Error("section plane", …) when nothing visible is left.
Scene sectionedScene(const Scene& scene, SectionReport* report = nullptr);

// The plane of a section as (n, d), n unit length, kept where dot(n, p) + d >= 0 (world space).
glm::dvec4 sectionPlaneEquation(const SectionPlane& plane);

}  // namespace mfr
