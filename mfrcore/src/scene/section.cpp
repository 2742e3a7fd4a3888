#include "mfr/scene/section.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <ranges>
#include <tuple>
#include <unordered_map>
#include <utility>

#include <vtkCellArray.h>
#include <vtkContourTriangulator.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include "mfr/error.hpp"

namespace mfr {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// Cut-line endpoints closer than this fraction of a mesh's bounding-box diagonal are one point.
// Measured on the 2CylinderEngine's parts (glTF, split per face): their cut lines have gaps of
// 1e-6 to 7e-5 of the diagonal; at 1e-4, 19 of the 24 parts cut by z = 0 close (13 at 1e-6) and
// all 7 cut by x = 0 (5), 1e-3 adds only 2 of the 51 cut by y = 0.
constexpr double kCapWeld = 1e-4;

// The cap of one cut mesh, from its cut line: the segments exit → entry (indices into the cut mesh
// `m`) where its triangles cross the plane, in the surface's winding.
//
// Endpoints closer than kCapWeld of the mesh's size are merged (a CAD face's edge nodes, evaluated
// on each of its surfaces, differ by rounding); a segment repeated (a doubled triangle) counts once and
// a segment with its reverse (a two-sided sheet) cancels. The rest must form closed loops — every
// point entered as often as left — or the surface is open where the plane cuts it and gets no cap.
// vtkContourTriangulator fills the loops (outer boundaries and holes by their winding), and the cap
// is kept only if its area equals the area the loops enclose, to 0.1 %: a failed triangulation is
// dropped, never drawn. Returns whether the loops closed; `cap` gets the triangles (normal
// `outward`, counter-clockwise seen from that side; vertex colours from the cut when withColors).
bool buildCap(const Mesh& m, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& cutLine,
              const glm::dvec3& outward, double weldDistance, bool withColors, Mesh& cap) {
  // Weld: one id per grid cell of size weldDistance, looking at the neighbouring cells too.
  using Cell = std::tuple<long long, long long, long long>;
  std::map<Cell, std::vector<vtkIdType>> grid;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  std::vector<std::uint32_t> source;  // cut-mesh vertex of each welded point
  std::unordered_map<std::uint32_t, vtkIdType> idOf;
  const auto weld = [&](std::uint32_t v) {
    if (const auto it = idOf.find(v); it != idOf.end()) return it->second;
    const glm::dvec3 p(m.positions[v]);
    const Cell c{std::llround(p.x / weldDistance), std::llround(p.y / weldDistance), std::llround(p.z / weldDistance)};
    vtkIdType id = -1;
    for (long long dx = -1; dx <= 1 && id < 0; ++dx)
      for (long long dy = -1; dy <= 1 && id < 0; ++dy)
        for (long long dz = -1; dz <= 1 && id < 0; ++dz) {
          const auto near = grid.find({std::get<0>(c) + dx, std::get<1>(c) + dy, std::get<2>(c) + dz});
          if (near == grid.end()) continue;
          for (const vtkIdType q : near->second)
            if (glm::distance(p, glm::dvec3(m.positions[source[static_cast<std::size_t>(q)]])) <= weldDistance) {
              id = q;
              break;
            }
        }
    if (id < 0) {
      id = points->InsertNextPoint(p.x, p.y, p.z);
      source.push_back(v);
      grid[c].push_back(id);
    }
    idOf.emplace(v, id);
    return id;
  };
  std::map<std::pair<vtkIdType, vtkIdType>, int> segments;  // directed, counted once
  for (const auto& [a, b] : cutLine) {
    const vtkIdType i = weld(a), j = weld(b);
    if (i != j) segments[{i, j}] = 1;
  }
  for (auto& [segment, keep] : segments)  // a segment and its reverse cancel
    if (const auto back = segments.find({segment.second, segment.first}); back != segments.end()) keep = 0;
  std::vector<int> balance(static_cast<std::size_t>(points->GetNumberOfPoints()), 0);
  vtkNew<vtkCellArray> lines;
  glm::dvec3 centre(0.0);
  for (const vtkIdType id : std::views::iota(vtkIdType{0}, points->GetNumberOfPoints()))
    centre += glm::dvec3(m.positions[source[static_cast<std::size_t>(id)]]);
  centre /= std::max<double>(1.0, static_cast<double>(points->GetNumberOfPoints()));
  double enclosed = 0.0;  // about `centre`, along -outward (the cut line's own winding)
  for (const auto& [segment, keep] : segments) {
    if (!keep) continue;
    ++balance[static_cast<std::size_t>(segment.first)];
    --balance[static_cast<std::size_t>(segment.second)];
    const vtkIdType ids[2] = {segment.first, segment.second};
    lines->InsertNextCell(2, ids);
    const glm::dvec3 a = glm::dvec3(m.positions[source[static_cast<std::size_t>(segment.first)]]) - centre;
    const glm::dvec3 b = glm::dvec3(m.positions[source[static_cast<std::size_t>(segment.second)]]) - centre;
    enclosed -= 0.5 * glm::dot(glm::cross(a, b), outward);
  }
  if (lines->GetNumberOfCells() < 3) return false;
  if (std::any_of(balance.begin(), balance.end(), [](int b) { return b != 0; })) return false;

  vtkNew<vtkPolyData> contours;
  contours->SetPoints(points);
  contours->SetLines(lines);
  vtkNew<vtkCellArray> triangles;
  const double normal[3] = {-outward.x, -outward.y, -outward.z};
  (void)vtkContourTriangulator::TriangulateContours(contours, 0, lines->GetNumberOfCells(), triangles, normal);
  Mesh filled;
  double area = 0.0;
  const vtkIdType* ids = nullptr;
  vtkIdType count = 0;
  for (triangles->InitTraversal(); triangles->GetNextCell(count, ids);) {
    if (count != 3) continue;
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = glm::dvec3(m.positions[source[static_cast<std::size_t>(ids[k])]]);
    const double facing = glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), outward);
    if (facing == 0.0) continue;
    area += 0.5 * std::abs(facing);
    const int order[3] = {0, facing > 0.0 ? 1 : 2, facing > 0.0 ? 2 : 1};
    for (const int k : order) {
      filled.indices.push_back(static_cast<std::uint32_t>(filled.positions.size()));
      filled.positions.emplace_back(p[k]);
      filled.normals.emplace_back(outward);
      if (withColors) filled.colors.push_back(m.colors[source[static_cast<std::size_t>(ids[k])]]);
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
  std::vector<double> s(mesh.positions.size());
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = glm::dot(n, glm::dvec3(mesh.positions[i])) + plane.w;
  bool anyKept = false, anyRemoved = false;
  for (const std::uint32_t i : mesh.indices) (s[i] >= 0.0 ? anyKept : anyRemoved) = true;
  if (!anyRemoved) return out;
  if (!anyKept) {
    out.outcome = SectionOutcome::kRemoved;
    return out;
  }

  Mesh& m = out.mesh;
  const bool hasNormals = !mesh.normals.empty(), hasColors = !mesh.colors.empty();
  std::vector<std::uint32_t> keptIndex(mesh.positions.size(), kNone);
  const auto keep = [&](std::uint32_t i) {
    if (keptIndex[i] == kNone) {
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
    std::uint32_t exit = kNone, entry = kNone;  // where the winding leaves and re-enters the kept side
    for (int k = 0; k < 3; ++k) {
      const int next = (k + 1) % 3;
      if (kept[k]) polygon[corners++] = keep(v[k]);
      if (kept[k] != kept[next]) {
        polygon[corners] = kept[k] ? cut(v[k], v[next]) : cut(v[next], v[k]);
        (kept[k] ? exit : entry) = polygon[corners++];
      }
    }
    if (exit != kNone && entry != kNone && exit != entry) cutLine.emplace_back(exit, entry);
    for (int k = 1; k + 1 < corners; ++k) {
      if (polygon[0] == polygon[k] || polygon[k] == polygon[k + 1] || polygon[0] == polygon[k + 1]) continue;
      m.indices.insert(m.indices.end(), {polygon[0], polygon[k], polygon[k + 1]});
    }
  }
  out.outcome = SectionOutcome::kCut;
  if (caps && !m.indices.empty()) {
    const Bounds box = mesh.bounds();
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
