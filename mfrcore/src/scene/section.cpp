#include "mfr/scene/section.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <tuple>
#include <unordered_map>
#include <utility>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include "mfr/error.hpp"

namespace mfr {
namespace {

constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t kNoPoint = std::numeric_limits<std::size_t>::max();
// A chain of the cut line that ends this close (a fraction of the mesh's bounding-box diagonal) to
// where another starts is joined to it. Measured on the 2CylinderEngine's parts (glTF, split per
// face): their cut lines have gaps of 1e-6 to 7e-5 of the diagonal; at 1e-4, 19 of the 24 parts
// cut by z = 0 close (13 at 1e-6), all 7 cut by x = 0 (5) and 38 of the 51 cut by y = 0 (36);
// 1e-3 adds only 2 of those 51.
constexpr double kCapWeld = 1e-4;

// Faces of the cap's triangulation: how many constrained edges (cut-line segments) separate them
// from the outside; odd is inside the section.
struct CapFace {
  int nesting = -1;
};
using CapKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CapTds =
    CGAL::Triangulation_data_structure_2<CGAL::Triangulation_vertex_base_with_info_2<std::size_t, CapKernel>,
                                         CGAL::Constrained_triangulation_face_base_2<
                                             CapKernel, CGAL::Triangulation_face_base_with_info_2<CapFace, CapKernel>>>;
// Crossing segments (a self-intersecting cut line) throw instead of inventing points.
using CapTriangulation =
    CGAL::Constrained_Delaunay_triangulation_2<CapKernel, CapTds, CGAL::No_constraint_intersection_tag>;

// Breadth-first from the infinite face: each region bounded by constrained edges gets one more
// than the region it was reached from.
void markNesting(CapTriangulation& cdt) {
  for (const CapTriangulation::Face_handle f : cdt.all_face_handles()) f->info().nesting = -1;
  std::vector<CapTriangulation::Edge> border;
  const auto flood = [&](CapTriangulation::Face_handle start, int nesting) {
    std::vector<CapTriangulation::Face_handle> queue{start};
    while (!queue.empty()) {
      const CapTriangulation::Face_handle f = queue.back();
      queue.pop_back();
      if (f->info().nesting != -1) continue;
      f->info().nesting = nesting;
      for (int i = 0; i < 3; ++i) {
        const CapTriangulation::Face_handle next = f->neighbor(i);
        if (next->info().nesting != -1) continue;
        if (cdt.is_constrained({f, i}))
          border.emplace_back(f, i);
        else
          queue.push_back(next);
      }
    }
  };
  flood(cdt.infinite_face(), 0);
  while (!border.empty()) {
    const CapTriangulation::Edge e = border.back();
    border.pop_back();
    const CapTriangulation::Face_handle next = e.first->neighbor(e.second);
    if (next->info().nesting == -1) flood(next, e.first->info().nesting + 1);
  }
}

// The cap of one cut mesh, from its cut line: the segments exit → entry (indices into the cut mesh
// `m`) where its triangles cross the plane, in the surface's winding.
//
// Points at the same position are one; a segment repeated (a doubled triangle) counts once and a
// segment with its reverse (a two-sided sheet) cancels; a chain that ends within kCapWeld of the
// mesh's size of where another starts is joined to it (a CAD face's edge nodes, evaluated on each
// of its surfaces, differ by rounding). The rest must form closed loops — every point entered as
// often as left — or the surface is open where the plane cuts it and gets no cap.
// CGAL's constrained Delaunay triangulation fills the loops (inside: an odd number of loops around),
// keeping every cut point as a vertex, so the cap meets the cut surface edge to edge (watertight).
// The cap is kept only if its area equals the area the loops enclose, to 0.1 %: a failed fill is
// dropped, never drawn. Returns whether the loops closed; `cap` gets the triangles (normal
// `outward`, counter-clockwise seen from that side; vertex colours from the cut when withColors).
bool buildCap(const Mesh& m, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& cutLine,
              const glm::dvec3& outward, double weldDistance, bool withColors, Mesh& cap) {
  // Points: cut vertices at the same position are one (a mesh split per face cuts each face's copy
  // of an edge to the same bits).
  std::map<std::tuple<float, float, float>, std::size_t> idAt;
  std::vector<std::uint32_t> source;  // cut-mesh vertex of each point
  const auto position = [&](std::size_t id) { return glm::dvec3(m.positions[source[id]]); };
  const auto pointOf = [&](std::uint32_t v) {
    const glm::vec3& p = m.positions[v];
    const auto [it, inserted] = idAt.try_emplace({p.x, p.y, p.z}, source.size());
    if (inserted) source.push_back(v);
    return it->second;
  };
  std::vector<std::pair<std::size_t, std::size_t>> raw;
  raw.reserve(cutLine.size());
  for (const auto& [a, b] : cutLine) raw.emplace_back(pointOf(a), pointOf(b));

  // Segments between distinct points, counted once; a segment and its reverse cancel.
  std::vector<std::size_t> root(source.size());
  for (std::size_t i = 0; i < root.size(); ++i) root[i] = i;
  const auto find = [&](std::size_t i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  std::map<std::pair<std::size_t, std::size_t>, bool> segments;
  std::vector<int> balance;
  const auto collect = [&] {
    segments.clear();
    for (const auto& [a, b] : raw)
      if (const std::size_t i = find(a), j = find(b); i != j) segments[{i, j}] = true;
    for (auto& [segment, keep] : segments)
      if (segments.contains({segment.second, segment.first})) keep = false;
    balance.assign(source.size(), 0);
    for (const auto& [segment, keep] : segments)
      if (keep) {
        ++balance[segment.first];
        --balance[segment.second];
      }
  };
  collect();
  // Gaps: where a chain ends (more entered than left) and another starts (more left than entered)
  // within weldDistance, the two are one point — the nearest pairs first. Points that close
  // already are never moved, so a fine tessellation keeps every cut point.
  std::vector<std::tuple<double, std::size_t, std::size_t>> gaps;
  for (std::size_t e = 0; e < balance.size(); ++e)
    if (balance[e] < 0)
      for (std::size_t b = 0; b < balance.size(); ++b)
        if (balance[b] > 0)
          if (const double d = glm::distance(position(e), position(b)); d <= weldDistance) gaps.emplace_back(d, e, b);
  if (!gaps.empty()) {
    std::sort(gaps.begin(), gaps.end());
    std::vector<int> open = balance;
    for (const auto& [d, e, b] : gaps) {
      if (open[e] >= 0 || open[b] <= 0 || find(e) == find(b)) continue;
      ++open[e];
      --open[b];
      root[find(b)] = find(e);
    }
    collect();
  }
  std::size_t kept = 0;
  for (const auto& [segment, keep] : segments) kept += keep ? 1 : 0;
  if (kept < 3) return false;
  if (std::any_of(balance.begin(), balance.end(), [](int b) { return b != 0; })) return false;

  // The plane's own 2D frame, about the cut line's centre.
  glm::dvec3 centre(0.0);
  for (std::size_t id = 0; id < source.size(); ++id) centre += position(id);
  centre /= static_cast<double>(source.size());
  const glm::dvec3 u = glm::normalize(glm::abs(outward.x) < 0.9 ? glm::cross(outward, glm::dvec3(1.0, 0.0, 0.0))
                                                                : glm::cross(outward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dvec3 v = glm::cross(outward, u);
  CapTriangulation cdt;
  std::vector<CapTriangulation::Vertex_handle> handle(source.size());
  double enclosed = 0.0;  // about `centre`, along -outward (the cut line's own winding)
  try {
    for (std::size_t id = 0; id < source.size(); ++id) {
      if (find(id) != id) continue;  // merged into its root
      const glm::dvec3 p = position(id) - centre;
      handle[id] = cdt.insert(CapKernel::Point_2(glm::dot(p, u), glm::dot(p, v)));
      handle[id]->info() = id;
    }
    for (const auto& [segment, keep] : segments) {
      if (!keep) continue;
      if (handle[segment.first] == handle[segment.second]) return true;  // two points in one: no cap
      cdt.insert_constraint(handle[segment.first], handle[segment.second]);
      enclosed -=
          0.5 * glm::dot(glm::cross(position(segment.first) - centre, position(segment.second) - centre), outward);
    }
  } catch (const CapTriangulation::Intersection_of_constraints_exception&) {
    return true;  // the cut line crosses itself: closed, but no cap
  }
  markNesting(cdt);

  Mesh filled;
  double area = 0.0;
  for (const CapTriangulation::Face_handle f : cdt.finite_face_handles()) {
    if (f->info().nesting % 2 != 1) continue;
    std::size_t ids[3];
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k) {
      ids[k] = f->vertex(k)->info();
      p[k] = position(ids[k]);
    }
    const double facing = glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), outward);
    if (facing == 0.0) continue;
    area += 0.5 * std::abs(facing);
    const int order[3] = {0, facing > 0.0 ? 1 : 2, facing > 0.0 ? 2 : 1};
    for (const int k : order) {
      filled.indices.push_back(static_cast<std::uint32_t>(filled.positions.size()));
      filled.positions.emplace_back(p[k]);
      filled.normals.emplace_back(outward);
      if (withColors) filled.colors.push_back(m.colors[source[ids[k]]]);
    }
  }
  if (area > 0.0 && std::abs(area - enclosed) <= 1e-3 * area) cap = std::move(filled);
  return true;
}

}  // namespace

glm::dvec4 sectionPlaneEquation(const SectionPlane& plane) {
  validateSectionPlane(plane, "section plane");
  const glm::dvec3 n = glm::normalize(plane.normal);
  return {n, -glm::dot(n, plane.point)};
}

SectionedMesh sectionMesh(const Mesh& mesh, const glm::dvec4& plane, bool caps) {
  SectionedMesh out;
  const glm::dvec3 n(plane);
  // Signed distances; those within 1e-9 of the mesh's size are on the plane. A part turned by 90°
  // has vertices at 1e-17 instead of 0 (cos 90° in double), on either side: cutting the edges
  // between them would put cut points anywhere along edges that lie in the plane.
  const Bounds box = mesh.bounds();
  const double onPlane = 1e-9 * glm::length(box.max - box.min) * glm::length(n);
  std::vector<double> s(mesh.positions.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i] = glm::dot(n, glm::dvec3(mesh.positions[i])) + plane.w;
    if (std::abs(s[i]) <= onPlane) s[i] = 0.0;
  }
  bool anyKept = false, anyRemoved = false;
  for (const std::uint32_t i : mesh.indices) (s[i] >= 0.0 ? anyKept : anyRemoved) = true;
  if (!anyRemoved) return out;
  if (!anyKept) {
    out.outcome = SectionOutcome::kRemoved;
    return out;
  }

  Mesh& m = out.mesh;
  const bool hasNormals = !mesh.normals.empty(), hasColors = !mesh.colors.empty();
  std::vector<std::uint32_t> keptIndex(mesh.positions.size(), kNoVertex);
  const auto keep = [&](std::uint32_t i) {
    if (keptIndex[i] == kNoVertex) {
      keptIndex[i] = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back(mesh.positions[i]);
      if (hasNormals) m.normals.push_back(mesh.normals[i]);
      if (hasColors) m.colors.push_back(mesh.colors[i]);
    }
    return keptIndex[i];
  };
  // The point where edge (a kept, b removed) meets the plane, made once per edge so that the two
  // triangles sharing the edge share the vertex (no crack along the cut).
  std::unordered_map<std::uint64_t, std::uint32_t> cutVertex;
  const auto cut = [&](std::uint32_t a, std::uint32_t b) {
    if (s[a] == 0.0) return keep(a);  // on the plane: the vertex itself
    const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | b;
    const auto [it, inserted] = cutVertex.try_emplace(key, static_cast<std::uint32_t>(m.positions.size()));
    if (!inserted) return it->second;
    const double t = s[a] / (s[a] - s[b]);
    m.positions.emplace_back(glm::mix(glm::dvec3(mesh.positions[a]), glm::dvec3(mesh.positions[b]), t));
    if (hasNormals) {
      const glm::dvec3 normal = glm::mix(glm::dvec3(mesh.normals[a]), glm::dvec3(mesh.normals[b]), t);
      const double length = glm::length(normal);
      m.normals.push_back(length > 0.0 ? glm::vec3(normal / length) : mesh.normals[a]);
    }
    if (hasColors) m.colors.push_back(glm::vec4(glm::mix(glm::dvec4(mesh.colors[a]), glm::dvec4(mesh.colors[b]), t)));
    return it->second;
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> cutLine;  // on the plane, in the surface's winding
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const std::uint32_t v[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
    const bool kept[3] = {s[v[0]] >= 0.0, s[v[1]] >= 0.0, s[v[2]] >= 0.0};
    if (!kept[0] && !kept[1] && !kept[2]) continue;
    // The kept part, in the triangle's winding: 3 or 4 corners (one cut edge pair).
    std::uint32_t polygon[4];
    int corners = 0;
    std::uint32_t exit = kNoVertex, entry = kNoVertex;  // where the winding leaves and re-enters the kept side
    for (int k = 0; k < 3; ++k) {
      const int next = (k + 1) % 3;
      if (kept[k]) polygon[corners++] = keep(v[k]);
      if (kept[k] != kept[next]) {
        polygon[corners] = kept[k] ? cut(v[k], v[next]) : cut(v[next], v[k]);
        (kept[k] ? exit : entry) = polygon[corners++];
      }
    }
    if (exit != kNoVertex && entry != kNoVertex && exit != entry) cutLine.emplace_back(exit, entry);
    for (int k = 1; k + 1 < corners; ++k) {
      if (polygon[0] == polygon[k] || polygon[k] == polygon[k + 1] || polygon[0] == polygon[k + 1]) continue;
      m.indices.insert(m.indices.end(), {polygon[0], polygon[k], polygon[k + 1]});
    }
  }
  out.outcome = SectionOutcome::kCut;
  if (caps && !m.indices.empty()) {
    const double weldDistance = std::max(kCapWeld * glm::length(box.max - box.min), 1e-30);
    Mesh cap;
    out.closed = buildCap(m, cutLine, -glm::normalize(n), weldDistance, hasColors, cap);
    if (!cap.indices.empty()) {
      out.capTriangles = cap.triangleCount();
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      m.positions.insert(m.positions.end(), cap.positions.begin(), cap.positions.end());
      if (hasNormals) m.normals.insert(m.normals.end(), cap.normals.begin(), cap.normals.end());
      if (hasColors) m.colors.insert(m.colors.end(), cap.colors.begin(), cap.colors.end());
      for (const std::uint32_t i : cap.indices) m.indices.push_back(base + i);
      out.outcome = SectionOutcome::kCapped;
    }
  }
  if (!hasNormals) m.computeSmoothNormals();
  return out;
}

Scene sectionedScene(const Scene& scene, SectionReport* report) {
  if (!scene.section || scene.sectionCut) return scene;
  const glm::dvec4 world = sectionPlaneEquation(*scene.section);
  const glm::dvec3 n(world);
  Scene out = scene;
  out.sectionCut = true;
  SectionReport local;
  for (Object& object : out.objects) {
    if (!object.visible || !object.mesh || object.mesh->triangleCount() == 0) continue;
    // World p = A·q + t: dot(n, A·q + t) + w = dot(Aᵀn, q) + dot(n, t) + w.
    const glm::dmat3 a(object.transform);
    const glm::dvec3 t(object.transform[3]);
    const glm::dvec4 plane(glm::transpose(a) * n, glm::dot(n, t) + world.w);
    if (!(glm::length(glm::dvec3(plane)) > 0.0)) continue;  // a flattened object: left as it is
    SectionedMesh cut = sectionMesh(*object.mesh, plane, scene.section->caps);
    switch (cut.outcome) {
      case SectionOutcome::kKept:
        break;
      case SectionOutcome::kRemoved:
        object.visible = false;
        ++local.removed;
        break;
      case SectionOutcome::kCut:
      case SectionOutcome::kCapped:
        ++local.cut;
        if (cut.outcome == SectionOutcome::kCapped) ++local.capped;
        if (scene.section->caps && cut.outcome == SectionOutcome::kCut) local.open.push_back(object.name);
        object.mesh = std::make_shared<const Mesh>(std::move(cut.mesh));
        break;
    }
  }
  if (out.triangleCount() == 0 && !out.visibleVolume())
    throw Error("section plane", "cuts away every visible surface of scene '" + scene.name + "'");
  if (report) *report = std::move(local);
  return out;
}

}  // namespace mfr
