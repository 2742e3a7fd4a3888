#pragma once
// Image-space CSG against an independent reference: CGAL's exact Booleans (Polygon_mesh_processing
// corefinement with exact constructions) of a scene's closed objects, cast by the oracle, compared
// pixel by pixel with csgVisibleFragment on the oracle's lists of the original scene. Shared by
// tests/unit/test_csg.cpp (generated solids) and tests/data/test_csg_step.cpp (a real STEP part).
// A translation unit including this needs -frounding-math (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "mfr/reference/oracle.hpp"
#include "mfr/scene/csg.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::test::csg {

inline void addObject(Scene& scene, const std::string& name, Mesh mesh, const glm::dmat4& transform = glm::dmat4(1.0),
                      const glm::vec4& color = {0.8f, 0.8f, 0.8f, 1.0f}) {
  Object o;
  o.name = name;
  o.mesh = std::make_shared<const Mesh>(std::move(mesh));
  o.transform = transform;
  o.material.color = color;
  scene.objects.push_back(std::move(o));
}

// The independent reference: CGAL's exact Booleans (corefinement, exact constructions), cast by
// the oracle, against csgVisibleFragment on the oracle's lists of the original scene.

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

// An object's mesh in world space as a CGAL surface mesh. Vertices are merged by object-space
// position rounded to 10⁻⁹ (the generated seams and poles differ in the last bits), so the result
// is a closed, valid polyhedral surface; the world positions are the oracle's (float position,
// transformed in double).
inline SurfaceMesh toCgal(const Object& object) {
  SurfaceMesh out;
  const Mesh& mesh = *object.mesh;
  std::map<std::array<long long, 3>, SurfaceMesh::Vertex_index> merged;
  std::vector<SurfaceMesh::Vertex_index> vertexOf(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::dvec3 p(mesh.positions[i]);
    const std::array<long long, 3> key = {std::llround(p.x * 1e9), std::llround(p.y * 1e9), std::llround(p.z * 1e9)};
    const auto it = merged.find(key);
    if (it != merged.end()) {
      vertexOf[i] = it->second;
      continue;
    }
    const glm::dvec3 w = glm::dvec3(object.transform * glm::dvec4(p, 1.0));
    vertexOf[i] = merged[key] = out.add_vertex(Kernel::Point_3(w.x, w.y, w.z));
  }
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const auto a = vertexOf[mesh.indices[t]], b = vertexOf[mesh.indices[t + 1]], c = vertexOf[mesh.indices[t + 2]];
    if (a == b || b == c || a == c) continue;
    EXPECT_NE(out.add_face(a, b, c), SurfaceMesh::null_face()) << object.name << ": non-manifold at triangle " << t / 3;
  }
  EXPECT_TRUE(CGAL::is_closed(out)) << object.name;
  EXPECT_FALSE(PMP::does_self_intersect(out)) << object.name;
  EXPECT_TRUE(PMP::does_bound_a_volume(out)) << object.name;
  EXPECT_TRUE(PMP::is_outward_oriented(out)) << object.name;
  return out;
}

// A CGAL result back as an mfr mesh in world space (vertices rounded to float as every mesh is).
inline Mesh toMfr(SurfaceMesh mesh) {
  PMP::triangulate_faces(mesh);
  Mesh out;
  std::map<SurfaceMesh::Vertex_index, std::uint32_t> index;
  for (const auto v : mesh.vertices()) {
    index[v] = static_cast<std::uint32_t>(out.positions.size());
    const Kernel::Point_3& p = mesh.point(v);
    out.positions.emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
  }
  for (const auto f : mesh.faces()) {
    int corners = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      out.indices.push_back(index.at(v));
      ++corners;
    }
    EXPECT_EQ(corners, 3);
  }
  out.computeSmoothNormals();
  return out;
}

enum class Boolean { Union, Intersection, Difference };

inline SurfaceMesh boolean(Boolean op, SurfaceMesh a, SurfaceMesh b) {  // copies: corefinement edits its inputs
  SurfaceMesh out;
  bool ok = false;
  switch (op) {
    case Boolean::Union:
      ok = PMP::corefine_and_compute_union(a, b, out);
      break;
    case Boolean::Intersection:
      ok = PMP::corefine_and_compute_intersection(a, b, out);
      break;
    case Boolean::Difference:
      ok = PMP::corefine_and_compute_difference(a, b, out);
      break;
  }
  EXPECT_TRUE(ok);
  EXPECT_TRUE(CGAL::is_closed(out));
  return out;
}

struct Comparison {
  int compared = 0;  // pixels flagged in neither cast
  int excluded = 0;  // flagged in either
  int hits = 0;      // compared pixels where both show a surface
  int mismatches = 0;
  std::map<std::uint32_t, int> shown;  // compared pixels with a surface, by the object shown
};

inline Camera perspectiveView() {
  Camera c;
  c.eye = {3.0, 2.5, 9.0};
  c.target = {0.0, 0.0, 0.0};
  c.up = {0.0, 1.0, 0.0};
  c.projection = Projection::Perspective;
  c.fovyDegrees = 27.0;
  c.nearPlane = 1.0;
  c.farPlane = 20.0;
  return c;
}

inline Camera orthographicView() {
  Camera c;
  c.eye = {-7.0, 3.0, 5.0};
  c.target = {0.0, 0.0, 0.0};
  c.up = {0.0, 1.0, 0.0};
  c.projection = Projection::Orthographic;
  c.orthoHeight = 4.6;
  c.nearPlane = 1.0;
  c.farPlane = 20.0;
  return c;
}

// On every pixel flagged in neither cast, the reference's first fragment exists exactly when the
// classification finds a visible fragment, at the same depth (10⁻⁵ relative).
inline Comparison compare(const Scene& csgScene, const Scene& reference, const Camera& camera, int size = 96) {
  const FragmentLists lists = castFragments(csgScene, camera, size, size);
  const FragmentLists expected = castFragments(reference, camera, size, size);
  Comparison c;
  std::ostringstream first;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      if (lists.isAmbiguous(x, y) || expected.isAmbiguous(x, y)) {
        ++c.excluded;
        continue;
      }
      ++c.compared;
      const auto sorted = lists.pixel(x, y);
      const auto want = expected.pixel(x, y);
      const std::optional<std::size_t> got = csgVisibleFragment(csgScene.csg, sorted, csgMirroredPrimitives(csgScene));
      bool same = got.has_value() == !want.empty();
      if (same && got) {
        ++c.hits;
        ++c.shown[sorted[*got].objectId];
        const double a = sorted[*got].depth, b = want[0].depth;
        same = std::abs(a - b) <= 1e-5 * std::max(a, b);
      }
      if (!same && ++c.mismatches <= 5)
        first << " (" << x << ", " << y << "): csg " << (got ? std::to_string(sorted[*got].depth) : "none") << ", CGAL "
              << (want.empty() ? "none" : std::to_string(want[0].depth)) << ";";
    }
  EXPECT_EQ(c.mismatches, 0) << "first mismatches:" << first.str();
  return c;
}

// Checks one scene and its reference in both views, prints the counts and requires few exclusions
// (under 15 %; 3–9 % when written) and many compared pixels with a surface: minHits is about 3/4
// of the count printed for the view with fewer, so a classification that loses surfaces fails.
// Every object of the CSG scene (a hole's walls included) must be what 50 pixels of the two views
// show.
inline void compareBothViews(const Scene& csgScene, const Scene& reference, int minHits) {
  std::map<std::uint32_t, int> shownInBoth;
  for (const auto& [label, camera] :
       {std::pair{"perspective", perspectiveView()}, std::pair{"orthographic", orthographicView()}}) {
    SCOPED_TRACE(label);
    const Comparison c = compare(csgScene, reference, camera);
    std::string shown;
    for (const auto& [object, count] : c.shown) {
      shown += " " + csgScene.objects[object].name + " " + std::to_string(count);
      shownInBoth[object] += count;
    }
    std::printf("[   CSG    ] %s %s: %d pixels compared (%d with a surface:%s), %d excluded (%.1f %%)\n",
                csgScene.name.c_str(), label, c.compared, c.hits, shown.c_str(), c.excluded,
                100.0 * c.excluded / (96 * 96));
    EXPECT_LT(c.excluded, 96 * 96 * 15 / 100);
    EXPECT_GT(c.hits, minHits);
  }
  for (std::uint32_t object = 0; object < csgScene.objects.size(); ++object)
    EXPECT_GE(shownInBoth[object], 50) << csgScene.objects[object].name;
}

inline Scene referenceScene(const std::string& name, SurfaceMesh result) {
  Scene s;
  s.name = name;
  addObject(s, "result", toMfr(std::move(result)));
  return s;
}

}  // namespace mfr::test::csg
