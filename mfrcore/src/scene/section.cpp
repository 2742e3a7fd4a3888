#include "mfr/scene/section.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_plus_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include "mfr/error.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/measure.hpp"
#include "mfr/list_text.hpp"

namespace mfr {
namespace {

constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();
// A chain of the cut line that ends this close (a fraction of the mesh's bounding-box diagonal) to
// where another starts is joined to it. Measured on the 2CylinderEngine's parts (glTF, split per
// face): their cut lines have gaps of 1e-6 to 7e-5 of the diagonal, and its two rods are split in
// two primitives with gaps of 2.6e-4 between them. Parts capped at 1e-6 / 1e-4 / 1e-3, with solids
// split over parts capped jointly (capJointly): z = 0 13 / 23 / 23 of 24, x = 0 5 / 7 / 7 of 7,
// y = 0 36 / 42 / 48 of 51 (each alone: 19 of 24, 7 of 7, 38 of 51 at 1e-4). Only open ends are
// joined, never points that close already, and the cap's area check stays the last word.
constexpr double kCapWeld = 1e-3;

// The cap's triangulation, in two kinds. Most cut lines are simple loops: CGAL's constrained
// Delaunay triangulation with inexact constructions fills them, and refuses (throws) where two
// segments cross or a point lies on a segment. Then — a self-intersecting surface: a cartoon
// folding over at a tight bend, two tubes of one part overlapping, shells meeting along a face —
// the cut line is triangulated again with exact constructions, each segment its own constraint of
// a Constrained_triangulation_plus_2, so that CGAL splits segments where they cross and still tells
// which segments, in which direction, run along each piece (inexact crossings could send a
// constraint on a detour through a nearby crossing).
constexpr std::size_t kCrossing = std::numeric_limits<std::size_t>::max();
struct CapPoint {
  std::size_t id = kCrossing;  // the cut-line point; kCrossing where two segments cross
};
struct CapFace {
  int winding = 0;
  bool reached = false;
};
template <class Kernel>
using CapTds = CGAL::Triangulation_data_structure_2<
    CGAL::Triangulation_vertex_base_with_info_2<CapPoint, Kernel>,
    CGAL::Constrained_triangulation_face_base_2<Kernel, CGAL::Triangulation_face_base_with_info_2<CapFace, Kernel>>>;
using SimpleKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SimpleCapTriangulation = CGAL::Constrained_Delaunay_triangulation_2<SimpleKernel, CapTds<SimpleKernel>,
                                                                          CGAL::No_constraint_intersection_tag>;
using CrossingKernel = CGAL::Exact_predicates_exact_constructions_kernel;
using CrossingCapTriangulation = CGAL::Constrained_triangulation_plus_2<
    CGAL::Constrained_Delaunay_triangulation_2<CrossingKernel, CapTds<CrossingKernel>, CGAL::Exact_intersections_tag>>;

// The winding number of every face about the cut line (the plane's 2D frame, counter-clockwise
// positive), breadth-first from the infinite face (0): crossing a constrained edge a → b from its
// left side changes it by across(a, b) — minus one per segment running a → b, plus one per segment
// running b → a. False if two paths to a face disagree (never for closed loops; kept as a check).
template <class Triangulation, class Across>
bool markWinding(Triangulation& cdt, const Across& across) {
  for (const typename Triangulation::Face_handle f : cdt.all_face_handles()) f->info() = CapFace{};
  std::vector<typename Triangulation::Face_handle> queue{cdt.infinite_face()};
  cdt.infinite_face()->info().reached = true;
  while (!queue.empty()) {
    const typename Triangulation::Face_handle f = queue.back();
    queue.pop_back();
    for (int i = 0; i < 3; ++i) {
      const typename Triangulation::Face_handle next = f->neighbor(i);
      // Face f lies left of its edge i run from vertex ccw(i) to vertex cw(i).
      const int winding =
          f->info().winding +
          (f->is_constrained(i) ? across(f->vertex(Triangulation::ccw(i)), f->vertex(Triangulation::cw(i))) : 0);
      if (next->info().reached) {
        if (next->info().winding != winding) return false;
        continue;
      }
      next->info() = {winding, true};
      queue.push_back(next);
    }
  }
  return true;
}

// A cut line welded into loops: the segments exit → entry (vertex indices into `positions`) where
// a surface's triangles cross the plane, in the surface's winding.
//
// Points at the same position are one; a segment with its reverse (a two-sided sheet) cancels. A
// segment repeated in one direction is either a doubled triangle's (or a shell listed twice): it
// counts once; or two shells' shared stretch (two boxes of one part side by side with a common
// face): it counts for each, so that both loops close. Each whole cut line is read the second way
// only if that leaves fewer open ends after welding. A chain that ends within `weldDistance` of
// where another starts is joined to it (a CAD face's edge nodes, evaluated on each of its surfaces,
// differ by rounding), the nearest pairs first. Points that close already are never moved, so a
// fine tessellation keeps every cut point.
struct WeldedCutLine {
  std::vector<std::uint32_t> source;                          // the vertex of each point
  std::vector<std::size_t> root;                              // union-find over points: a joined point's representative
  std::vector<std::pair<std::size_t, std::size_t>> segments;  // between representatives, kept ones
  std::vector<int> balance;  // per point: segments leaving minus entering; all 0 when the loops close

  std::size_t find(std::size_t i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  }
  bool closed() const {
    return segments.size() >= 3 && std::all_of(balance.begin(), balance.end(), [](int b) { return b == 0; });
  }
};

WeldedCutLine weldCutLine(const std::vector<glm::vec3>& positions,
                          const std::vector<std::pair<std::uint32_t, std::uint32_t>>& cutLine, double weldDistance) {
  WeldedCutLine w;
  std::map<std::tuple<float, float, float>, std::size_t> idAt;
  const auto pointOf = [&](std::uint32_t v) {
    const glm::vec3& p = positions[v];
    const auto [it, inserted] = idAt.try_emplace({p.x, p.y, p.z}, w.source.size());
    if (inserted) w.source.push_back(v);
    return it->second;
  };
  std::vector<std::pair<std::size_t, std::size_t>> raw;
  raw.reserve(cutLine.size());
  for (const auto& [a, b] : cutLine) raw.emplace_back(pointOf(a), pointOf(b));
  const auto position = [&](std::size_t id) { return glm::dvec3(positions[w.source[id]]); };

  // The cut line under one reading of repeated segments: its segments between representatives,
  // each as often as it is used more than its reverse (`repeated`), or once; then chains that end
  // near where another starts joined.
  const auto weld = [&](bool repeated) {
    WeldedCutLine line = w;
    line.root.resize(line.source.size());
    for (std::size_t i = 0; i < line.root.size(); ++i) line.root[i] = i;
    const auto collect = [&] {
      std::map<std::pair<std::size_t, std::size_t>, int> uses;  // (i < j): uses of i → j minus j → i
      std::map<std::pair<std::size_t, std::size_t>, bool> present;
      for (const auto& [a, b] : raw)
        if (const std::size_t i = line.find(a), j = line.find(b); i != j) {
          uses[{std::min(i, j), std::max(i, j)}] += i < j ? 1 : -1;
          present[{i, j}] = true;
        }
      line.segments.clear();
      line.balance.assign(line.source.size(), 0);
      for (const auto& [pair, net] : uses) {
        const auto [i, j] = pair;
        // Once: a segment and its reverse cancel outright, however often each is used.
        const int times = repeated ? std::abs(net) : (present.contains({i, j}) && present.contains({j, i}) ? 0 : 1);
        for (int k = 0; k < times; ++k) {
          const auto segment = net > 0 ? std::pair{i, j} : std::pair{j, i};
          line.segments.push_back(segment);
          ++line.balance[segment.first];
          --line.balance[segment.second];
        }
      }
    };
    collect();
    std::vector<std::tuple<double, std::size_t, std::size_t>> gaps;
    for (std::size_t e = 0; e < line.balance.size(); ++e)
      if (line.balance[e] < 0)
        for (std::size_t b = 0; b < line.balance.size(); ++b)
          if (line.balance[b] > 0)
            if (const double d = glm::distance(position(e), position(b)); d <= weldDistance) gaps.emplace_back(d, e, b);
    if (!gaps.empty()) {
      std::sort(gaps.begin(), gaps.end());
      std::vector<int> open = line.balance;
      for (const auto& [d, e, b] : gaps) {
        if (open[e] >= 0 || open[b] <= 0 || line.find(e) == line.find(b)) continue;
        ++open[e];
        --open[b];
        line.root[line.find(b)] = line.find(e);
      }
      collect();
    }
    return line;
  };
  const auto openEnds = [](const WeldedCutLine& line) {
    return std::count_if(line.balance.begin(), line.balance.end(), [](int b) { return b != 0; });
  };
  // Counting repeats for each use only where that leaves fewer open ends: a shell listed twice
  // closes either way and means one shell.
  WeldedCutLine once = weld(false);
  if (openEnds(once) == 0) return once;
  WeldedCutLine each = weld(true);
  return openEnds(each) < openEnds(once) ? each : once;
}

// The cap of a closed cut line. CGAL's constrained Delaunay triangulation fills the loops by the
// nonzero winding rule — inside where the loops wind around a point at all, so overlapping loops
// are filled once and a hole wound the other way stays open — keeping every cut point as a vertex,
// so the cap meets the cut surface edge to edge (watertight; where two segments cross, the cap gets
// a vertex at the crossing). A region the loops wind around the wrong way (an inside-out surface)
// is capped facing the other way, as that surface faces. The cap is kept only if the areas of its
// faces, each times its winding number, add up to the signed area the loops enclose, to 0.1 %: a
// failed fill is dropped, never drawn.
struct Cap {
  // The cap's triangles, counter-clockwise seen from `outward` (or from −outward where `inward`):
  // indices into `positions`, then into `crossings` from positions.size() on. Empty: no cap.
  std::vector<std::uint32_t> corners;
  std::vector<bool> inward;           // per triangle: faces −outward (an inside-out surface's cap)
  std::vector<glm::dvec3> crossings;  // where two segments of the cut line cross
  std::vector<std::size_t> beside;    // per crossing: the vertex of `positions` nearest to it on the line
};

// fillCap with one kind of triangulation; false when the simple kind refuses crossing segments.
template <class Triangulation>
bool fillCapWith(const std::vector<glm::vec3>& positions, const WeldedCutLine& line, const glm::dvec3& outward,
                 Cap& cap) {
  using Kernel = typename Triangulation::Geom_traits;
  using Vertex = typename Triangulation::Vertex_handle;
  constexpr bool crossings = requires(Triangulation t, Vertex a) {
    t.contexts_begin(a, a);
  };
  cap = Cap{};
  const auto position = [&](std::size_t id) { return glm::dvec3(positions[line.source[id]]); };
  // The plane's own 2D frame (u × v = outward), about the cut line's centre. Outward solids wind
  // −1 around their cap in it (their cut line runs clockwise seen from outside).
  glm::dvec3 centre(0.0);
  for (std::size_t id = 0; id < line.source.size(); ++id) centre += position(id);
  centre /= static_cast<double>(line.source.size());
  const glm::dvec3 u = glm::normalize(glm::abs(outward.x) < 0.9 ? glm::cross(outward, glm::dvec3(1.0, 0.0, 0.0))
                                                                : glm::cross(outward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dvec3 v = glm::cross(outward, u);
  Triangulation cdt;
  std::vector<Vertex> handle(line.source.size());
  double enclosed = 0.0;  // about `centre`, along outward
  for (std::size_t id = 0; id < line.source.size(); ++id) {
    if (line.root[id] != id) continue;  // joined to its representative
    const glm::dvec3 p = position(id) - centre;
    handle[id] = cdt.insert(typename Kernel::Point_2(glm::dot(p, u), glm::dot(p, v)));
    if (handle[id]->info().id != kCrossing) return true;  // two points in one: no cap
    handle[id]->info().id = id;
  }
  // The simple kind: each constrained edge is one segment (or a repeated one), whose direction and
  // number of uses are kept here.
  std::unordered_map<std::uint64_t, int> direction;  // (a, b) as a << 32 | b, point ids
  const auto key = [](Vertex a, Vertex b) {
    return static_cast<std::uint64_t>(a->info().id) << 32 | static_cast<std::uint64_t>(b->info().id);
  };
  try {
    for (const auto& [a, b] : line.segments) {
      cdt.insert_constraint(handle[a], handle[b]);
      if constexpr (!crossings) ++direction[key(handle[a], handle[b])];
      enclosed += 0.5 * glm::dot(glm::cross(position(a) - centre, position(b) - centre), outward);
    }
  } catch (const typename SimpleCapTriangulation::Intersection_of_constraints_exception&) {
    return false;
  }
  if (cdt.dimension() < 2) return true;  // every point on one line: nothing enclosed
  const auto across = [&](Vertex a, Vertex b) {
    int change = 0;
    if constexpr (crossings) {
      for (auto context = cdt.contexts_begin(a, b); context != cdt.contexts_end(a, b); ++context)
        change += *context->current() == a ? -1 : 1;
    } else {
      if (const auto it = direction.find(key(a, b)); it != direction.end()) change -= it->second;
      if (const auto it = direction.find(key(b, a)); it != direction.end()) change += it->second;
    }
    return change;
  };
  if (!markWinding(cdt, across)) return true;

  // Crossings become points of the cap, in the plane, coloured as the nearer end of a segment
  // through them.
  std::vector<std::uint32_t> index(line.source.size());
  for (std::size_t id = 0; id < line.source.size(); ++id) index[id] = line.source[id];
  if constexpr (crossings) {
    for (const Vertex vertex : cdt.finite_vertex_handles()) {
      if (vertex->info().id != kCrossing) continue;
      const auto& q = vertex->point();
      const glm::dvec3 at = centre + CGAL::to_double(q.x()) * u + CGAL::to_double(q.y()) * v;
      std::size_t nearest = kCrossing;
      double distance = std::numeric_limits<double>::infinity();
      auto around = cdt.incident_vertices(vertex), first = around;
      do {
        if (cdt.is_infinite(around) || !cdt.is_subconstraint(vertex, around)) continue;
        // The segment's ends: the first and last vertices of its constraint.
        for (auto context = cdt.contexts_begin(vertex, around); context != cdt.contexts_end(vertex, around);
             ++context) {
          Vertex last = *context->vertices_begin();
          for (auto it = context->vertices_begin(); it != context->vertices_end(); ++it) last = *it;
          for (const Vertex end : {*context->vertices_begin(), last})
            if (end->info().id < line.source.size())
              if (const double d = glm::distance(at, position(end->info().id)); d < distance) {
                distance = d;
                nearest = end->info().id;
              }
        }
      } while (++around != first);
      if (nearest == kCrossing) return true;  // never: a crossing lies on segments between cut points
      vertex->info().id = index.size();
      index.push_back(static_cast<std::uint32_t>(positions.size() + cap.crossings.size()));
      cap.crossings.push_back(at);
      cap.beside.push_back(line.source[nearest]);
    }
  }
  const auto pointOf = [&](std::size_t id) {
    return id < line.source.size() ? position(id) : cap.crossings[id - line.source.size()];
  };

  std::vector<std::uint32_t> filled;
  std::vector<bool> inward;
  double area = 0.0, wound = 0.0;
  for (const typename Triangulation::Face_handle f : cdt.finite_face_handles()) {
    const int winding = f->info().winding;
    if (winding == 0) continue;
    std::size_t ids[3];
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k) {
      ids[k] = f->vertex(k)->info().id;
      p[k] = pointOf(ids[k]);
    }
    const double facing = glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), outward);
    if (facing == 0.0) continue;
    area += 0.5 * std::abs(facing);
    wound += 0.5 * facing * winding;
    // Counter-clockwise seen from outward where the loops wind as an outward solid's (negative),
    // from −outward where they wind the other way.
    const bool flip = (facing > 0.0) == (winding > 0);
    const int order[3] = {0, flip ? 2 : 1, flip ? 1 : 2};
    for (const int k : order) filled.push_back(index[ids[k]]);
    inward.push_back(winding > 0);
  }
  if (area > 0.0 && std::abs(wound - enclosed) <= 1e-3 * area) {
    cap.corners = std::move(filled);
    cap.inward = std::move(inward);
  } else {
    cap = Cap{};
  }
  return true;
}

Cap fillCap(const std::vector<glm::vec3>& positions, const WeldedCutLine& line, const glm::dvec3& outward) {
  Cap cap;
  if (!fillCapWith<SimpleCapTriangulation>(positions, line, outward, cap))
    fillCapWith<CrossingCapTriangulation>(positions, line, outward, cap);
  return cap;
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
  const double size = glm::length(box.max - box.min) * glm::length(n);
  const double onPlane = 1e-9 * size;
  std::vector<double> s(mesh.positions.size());
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = glm::dot(n, glm::dvec3(mesh.positions[i])) + plane.w;
  bool anyKept = false, anyRemoved = false, anyOn = false;
  for (const std::uint32_t i : mesh.indices) {
    anyKept = anyKept || s[i] > onPlane;
    anyRemoved = anyRemoved || s[i] < -onPlane;
    anyOn = anyOn || std::abs(s[i]) <= onPlane;
  }
  // Touching the plane from one side is not being cut; a sheet lying in it is kept.
  if (!anyRemoved) return out;
  if (!anyKept) {
    out.outcome = SectionOutcome::kRemoved;
    return out;
  }
  // A part cut through with vertices on the plane — a face or an edge lying in it, common in CAD
  // parts cut at a round coordinate — is cut a millionth of its size further in instead, where no
  // vertex is: every cut edge then crosses the plane, and the cut line is made of crossings only.
  // (Edges lying in the plane would have to be matched against the faces beside them to close the
  // cut line.) If every tried offset meets a vertex, the vertices on the plane count as kept.
  double shift = 0.0;
  if (anyOn)
    for (double tryShift = 1e-6 * size; tryShift < 1e-5 * size && shift == 0.0; tryShift *= 1.37) {
      bool clear = true;
      for (const std::uint32_t i : mesh.indices) clear = clear && std::abs(s[i] - tryShift) > onPlane;
      if (clear) shift = tryShift;
    }
  for (double& d : s) {
    d -= shift;
    if (std::abs(d) <= onPlane) d = 0.0;
  }

  Mesh& m = out.mesh;
  const bool hasNormals = !mesh.normals.empty(), hasColors = !mesh.colors.empty(), hasScalars = !mesh.scalars.empty();
  std::vector<std::uint32_t> keptIndex(mesh.positions.size(), kNoVertex);
  const auto keep = [&](std::uint32_t i) {
    if (keptIndex[i] == kNoVertex) {
      keptIndex[i] = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back(mesh.positions[i]);
      if (hasNormals) m.normals.push_back(mesh.normals[i]);
      if (hasColors) m.colors.push_back(mesh.colors[i]);
      if (hasScalars) m.scalars.push_back(mesh.scalars[i]);
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
    if (hasScalars)
      m.scalars.push_back(static_cast<float>(glm::mix(double(mesh.scalars[a]), double(mesh.scalars[b]), t)));
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
  if (caps && !m.indices.empty() && cutLine.empty()) {
    // Only whole shells were removed (no triangle crosses the plane): nothing was opened. What is
    // kept needs no cap if it is closed (an open sheet kept stays reported as open).
    out.closed = true;
    if (measureSurface(m, glm::dmat4(1.0)).closed()) out.outcome = SectionOutcome::kCapped;
  } else if (caps && !m.indices.empty()) {
    const double weldDistance = std::max(kCapWeld * glm::length(box.max - box.min), 1e-30);
    WeldedCutLine line = weldCutLine(m.positions, cutLine, weldDistance);
    out.closed = line.closed();
    const Cap cap = out.closed ? fillCap(m.positions, line, -glm::normalize(n)) : Cap{};
    if (!cap.corners.empty()) {
      out.capTriangles = cap.corners.size() / 3;
      const glm::vec3 outward(-glm::normalize(n));
      const std::size_t cutVertices = m.positions.size();
      for (std::size_t k = 0; k < cap.corners.size(); ++k) {
        const std::uint32_t c = cap.corners[k];
        // A crossing takes its colour and value from the cut point beside it.
        const bool crossing = c >= cutVertices;
        const std::uint32_t from = crossing ? static_cast<std::uint32_t>(cap.beside[c - cutVertices]) : c;
        const glm::vec3 position = crossing ? glm::vec3(cap.crossings[c - cutVertices]) : m.positions[c];
        m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
        m.positions.push_back(position);
        if (hasNormals) m.normals.push_back(cap.inward[k / 3] ? -outward : outward);
        if (hasColors) {
          const glm::vec4 colour = m.colors[from];
          m.colors.push_back(colour);
        }
        // The cap is coloured by the field where the surface meets the plane, along its rim.
        if (hasScalars) {
          const float value = m.scalars[from];
          m.scalars.push_back(value);
        }
      }
      out.outcome = SectionOutcome::kCapped;
    } else {
      out.cutLine = std::move(cutLine);
      for (std::size_t p = 0; p < line.balance.size(); ++p)
        if (line.balance[p] != 0) out.openEnds.emplace_back(line.source[p], line.balance[p] < 0);
    }
  }
  if (!hasNormals) m.computeSmoothNormals();
  return out;
}

namespace {

// A part cut without a cap though caps were asked for, waiting for capJointly.
struct OpenCut {
  std::size_t object = 0;
  SectionedMesh cut;
  std::vector<glm::dvec3> world;  // the cut mesh's vertices in world space
  double diagonal = 0.0;          // of their bounding box
  bool mirrored = false;          // the transform turns its winding inside out
};

// Caps solids that are split over several parts: a glTF mesh with one primitive per material, or
// a CAD body exported face by face, is open part by part but closed as a whole. Parts whose cut
// lines end where another's start (within kCapWeld of the larger part's size) are grouped; a group
// whose joint cut line closes gets one cap, on the part with the most of that line (its colour;
// vertex colours from each part's cut, white where a part has none, so the owner's material shows).
// Returns, per entry of `open`, whether it was capped jointly.
std::vector<bool> capJointly(std::vector<Object>& objects, std::vector<OpenCut>& open, const glm::dvec3& outward) {
  std::vector<bool> capped(open.size(), false);
  // The open ends of each part's own cut line, in world space.
  struct End {
    glm::dvec3 position;
    std::size_t part;
    bool entering;  // more segments enter than leave
  };
  std::vector<End> ends;
  for (std::size_t i = 0; i < open.size(); ++i) {
    const OpenCut& part = open[i];
    for (const auto& [vertex, entering] : part.cut.openEnds)
      ends.push_back({part.world[vertex], i, entering != part.mirrored});
  }
  std::vector<std::size_t> group(open.size());
  for (std::size_t i = 0; i < group.size(); ++i) group[i] = i;
  const auto find = [&](std::size_t i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  double widest = 0.0;
  for (const OpenCut& part : open) widest = std::max(widest, kCapWeld * part.diagonal);
  std::sort(ends.begin(), ends.end(), [](const End& a, const End& b) { return a.position.x < b.position.x; });
  for (std::size_t a = 0; a < ends.size(); ++a)
    for (std::size_t b = a + 1; b < ends.size() && ends[b].position.x - ends[a].position.x <= widest; ++b) {
      const End &e = ends[a], &f = ends[b];
      if (e.part == f.part || e.entering == f.entering) continue;
      const double weld = kCapWeld * std::max(open[e.part].diagonal, open[f.part].diagonal);
      if (glm::distance(e.position, f.position) <= weld) group[find(e.part)] = find(f.part);
    }

  std::map<std::size_t, std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < open.size(); ++i) members[find(i)].push_back(i);
  for (const auto& member : members) {
    const std::vector<std::size_t>& parts = member.second;  // a name, not a binding: lambdas capture it
    if (parts.size() < 2) continue;
    // The group's cut lines as one, in world space; where each point came from.
    std::vector<glm::vec3> positions;
    std::vector<std::pair<std::size_t, std::uint32_t>> from;  // (part, vertex of its cut mesh)
    std::vector<std::pair<std::uint32_t, std::uint32_t>> cutLine;
    std::vector<std::size_t> share(parts.size(), 0);
    Bounds box;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const OpenCut& part = open[parts[k]];
      std::unordered_map<std::uint32_t, std::uint32_t> index;
      const auto pointOf = [&](std::uint32_t v) {
        const auto [it, inserted] = index.try_emplace(v, static_cast<std::uint32_t>(positions.size()));
        if (inserted) {
          positions.emplace_back(part.world[v]);
          box.extend(part.world[v]);
          from.emplace_back(parts[k], v);
        }
        return it->second;
      };
      // In world space a mirrored part's winding, and so its cut line, runs the other way.
      for (const auto& [a, b] : part.cut.cutLine)
        cutLine.push_back(part.mirrored ? std::pair(pointOf(b), pointOf(a)) : std::pair(pointOf(a), pointOf(b)));
      share[k] = part.cut.cutLine.size();
    }
    const WeldedCutLine line = weldCutLine(positions, cutLine, kCapWeld * glm::length(box.max - box.min));
    if (!line.closed()) continue;
    const Cap cap = fillCap(positions, line, outward);
    const std::vector<std::uint32_t>& corners = cap.corners;
    if (corners.empty()) continue;

    // The cap goes to the owner, in its object space.
    const std::size_t owner =
        parts[static_cast<std::size_t>(std::max_element(share.begin(), share.end()) - share.begin())];
    Mesh& m = open[owner].cut.mesh;
    const glm::dmat4& transform = objects[open[owner].object].transform;
    const glm::dmat4 toOwner = glm::inverse(transform);
    const glm::vec3 normal(glm::normalize(glm::transpose(glm::dmat3(transform)) * outward));
    const bool mirrored = glm::determinant(glm::dmat3(transform)) < 0.0;
    for (std::size_t c = 0; c < corners.size(); c += 3) {
      const std::uint32_t triangle[3] = {corners[c], corners[c + (mirrored ? 2 : 1)], corners[c + (mirrored ? 1 : 2)]};
      for (const std::uint32_t corner : triangle) {
        // A crossing of two cut lines takes its colour and value from the cut point beside it.
        const bool crossing = corner >= positions.size();
        const auto [part, v] = from[crossing ? cap.beside[corner - positions.size()] : corner];
        const Mesh& source = open[part].cut.mesh;
        const glm::vec3 position = crossing
                                       ? glm::vec3(toOwner * glm::dvec4(cap.crossings[corner - positions.size()], 1.0))
                                   : part == owner ? source.positions[v]
                                                   : glm::vec3(toOwner * glm::dvec4(open[part].world[v], 1.0));
        const glm::vec4 colour = source.colors.empty() ? glm::vec4(1.0f) : source.colors[v];
        const float value = source.scalars.empty() ? 0.0f : source.scalars[v];
        m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
        m.positions.push_back(position);
        if (!m.normals.empty()) m.normals.push_back(cap.inward[c / 3] ? -normal : normal);
        if (!m.colors.empty()) m.colors.push_back(colour);
        if (!m.scalars.empty()) m.scalars.push_back(value);
      }
    }
    open[owner].cut.capTriangles = corners.size() / 3;
    open[owner].cut.outcome = SectionOutcome::kCapped;
    for (const std::size_t part : parts) capped[part] = true;
  }
  return capped;
}

// The world area of the cap: the last capTriangles triangles of the cut mesh.
double capArea(const SectionedMesh& cut, const glm::dmat4& transform) {
  const Mesh& m = cut.mesh;
  double area = 0.0;
  const std::size_t triangles = m.triangleCount();
  for (std::size_t t = triangles - std::min(cut.capTriangles, triangles); t < triangles; ++t) {
    glm::dvec3 p[3];
    for (int c = 0; c < 3; ++c)
      p[c] = glm::dvec3(transform *
                        glm::dvec4(glm::dvec3(m.positions[m.indices[3 * t + static_cast<std::size_t>(c)]]), 1.0));
    area += 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
  }
  return area;
}

}  // namespace

std::string describeCut(SectionOutcome outcome, double capArea) {
  switch (outcome) {
    case SectionOutcome::kKept:
      return {};
    case SectionOutcome::kRemoved:
      return "removed by the section";
    case SectionOutcome::kCut:
      return "; cut";
    case SectionOutcome::kCapped:
      break;
  }
  // Capped by a group with other parts, or closed with nothing to cap (whole shells removed).
  if (!(capArea > 0.0)) return "; cut, closed without a cap of its own";
  std::ostringstream text;  // describeSurface's format: six significant digits
  text << "; cut, cross-section area " << capArea;
  return text.str();
}

double SectionReport::totalCapArea() const {
  double sum = 0.0;
  for (const double a : capAreas) sum += a;
  return sum;
}

std::vector<glm::dvec3> volumeSlicePolygon(const Volume& volume, const glm::dvec4& plane) {
  if (!volume.grid) return {};
  const glm::dvec3 n(plane);
  const glm::dmat4 toWorld = volume.gridToWorld();
  // The plane in grid coordinates (world p = A·g + t), then where it crosses the box's 12 edges.
  const glm::dmat3 a(toWorld);
  const glm::dvec3 t(toWorld[3]);
  const glm::dvec4 gridPlane(glm::transpose(a) * n, glm::dot(n, t) + plane.w);
  const glm::dvec3 last(volume.grid->dims - 1);
  const auto corner = [&](int i) {
    return glm::dvec3((i & 1) ? last.x : 0.0, (i & 2) ? last.y : 0.0, (i & 4) ? last.z : 0.0);
  };
  const double scale = glm::length(glm::dvec3(gridPlane)) * glm::length(last);
  // Each corner's side of the plane, corners on it (to rounding) on neither: a plane through a
  // face of the box then gives that face on both of its sides (one side had dropped it as a miss).
  const double onPlane = 1e-12 * scale;
  std::array<double, 8> distance{};
  std::array<int, 8> side{};
  for (int i = 0; i < 8; ++i) {
    distance[i] = glm::dot(glm::dvec3(gridPlane), corner(i)) + gridPlane.w;
    side[i] = distance[i] > onPlane ? 1 : distance[i] < -onPlane ? -1 : 0;
  }
  std::vector<glm::dvec3> points;
  const auto add = [&](const glm::dvec3& g) {
    const glm::dvec3 w(toWorld * glm::dvec4(g, 1.0));
    // A plane through a corner meets three edges there: one point.
    if (std::none_of(points.begin(), points.end(),
                     [&](const glm::dvec3& o) { return glm::length(o - w) <= 1e-9 * (1.0 + scale); }))
      points.push_back(w);
  };
  for (int i = 0; i < 8; ++i) {
    if (side[i] == 0) add(corner(i));
    for (int axis = 0; axis < 3; ++axis) {
      const int j = i | (1 << axis);
      if (j == i || side[i] * side[j] >= 0) continue;  // no edge crossed strictly between its ends
      add(corner(i) + (corner(j) - corner(i)) * (distance[i] / (distance[i] - distance[j])));
    }
  }
  if (points.size() < 3) return {};
  // Counter-clockwise about −n: sorted by angle in a basis (u, v) of the plane with u × v = −n.
  glm::dvec3 centre(0.0);
  for (const glm::dvec3& p : points) centre += p / static_cast<double>(points.size());
  const glm::dvec3 facing = -glm::normalize(n);
  const glm::dvec3 u = glm::normalize(points[0] - centre);
  const glm::dvec3 v = glm::cross(facing, u);
  std::sort(points.begin(), points.end(), [&](const glm::dvec3& p, const glm::dvec3& q) {
    return std::atan2(glm::dot(p - centre, v), glm::dot(p - centre, u)) <
           std::atan2(glm::dot(q - centre, v), glm::dot(q - centre, u));
  });
  // Only touching (every point on a line): no area.
  double area = 0.0;
  for (std::size_t i = 1; i + 1 < points.size(); ++i)
    area += glm::dot(glm::cross(points[i] - points[0], points[i + 1] - points[0]), facing);
  if (!(area > 1e-12 * glm::dot(volume.bounds().max - volume.bounds().min, volume.bounds().max - volume.bounds().min)))
    return {};
  return points;
}

namespace {

// SectionPlane::slice: volume v's slice as a part (sectionedScene's contract), `depth` behind the
// plane.
std::optional<Object> volumeSlice(const Scene& scene, std::size_t v, const glm::dvec4& plane, double depth) {
  const Volume& volume = scene.volumes[v];
  std::vector<glm::dvec3> polygon = volumeSlicePolygon(volume, plane);
  if (polygon.empty()) return std::nullopt;
  const glm::dvec3 inward = glm::normalize(glm::dvec3(plane)) * depth;
  auto mesh = std::make_shared<Mesh>();
  const glm::vec3 normal(-glm::normalize(glm::dvec3(plane)));
  for (const glm::dvec3& p : polygon) {
    mesh->positions.emplace_back(p + inward);
    mesh->normals.push_back(normal);
  }
  for (std::uint32_t i = 1; i + 1 < polygon.size(); ++i) mesh->indices.insert(mesh->indices.end(), {0u, i, i + 1});
  const std::string field = volumeFieldName(scene, v);
  Object slice;
  slice.name = field.substr(1) + " slice";
  slice.material.color = glm::vec4(1.0f);
  mesh->fields.push_back(VolumeFieldSampler::of(volume, glm::dmat4(1.0)).atVertices(field, *mesh));
  slice.mesh = std::move(mesh);
  colorByField(slice, field, "grayscale", glm::dvec2(volume.transfer.low(), volume.transfer.high()));
  return slice;
}

}  // namespace

Scene sectionedScene(const Scene& scene, SectionReport* report) {
  if (!scene.section || scene.sectionCut) return scene;
  const glm::dvec4 world = sectionPlaneEquation(*scene.section);
  const glm::dvec3 n(world);
  Scene out = scene;
  out.sectionCut = true;
  out.uncutExtent = std::pair{scene.bounds(), scene.boundingRadius()};
  SectionReport local;
  local.outcomes.assign(out.objects.size(), SectionOutcome::kKept);
  local.capAreas.assign(out.objects.size(), 0.0);
  std::vector<OpenCut> open;
  for (std::size_t i = 0; i < out.objects.size(); ++i) {
    Object& object = out.objects[i];
    if (!object.visible || !object.mesh || object.mesh->triangleCount() == 0) continue;
    // World p = A·q + t: dot(n, A·q + t) + w = dot(Aᵀn, q) + dot(n, t) + w.
    const glm::dmat3 a(object.transform);
    const glm::dvec3 t(object.transform[3]);
    const glm::dvec4 plane(glm::transpose(a) * n, glm::dot(n, t) + world.w);
    if (!(glm::length(glm::dvec3(plane)) > 0.0)) continue;  // a flattened object: left as it is
    SectionedMesh cut = sectionMesh(*object.mesh, plane, scene.section->caps);
    local.outcomes[i] = cut.outcome;
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
        if (scene.section->caps && cut.outcome == SectionOutcome::kCut && !cut.cutLine.empty()) {
          OpenCut part{i, std::move(cut), {}, 0.0};
          Bounds box;
          part.world.reserve(part.cut.mesh.positions.size());
          for (const glm::vec3& p : part.cut.mesh.positions) {
            part.world.emplace_back(object.transform * glm::dvec4(glm::dvec3(p), 1.0));
            box.extend(part.world.back());
          }
          part.diagonal = glm::length(box.max - box.min);
          part.mirrored = glm::determinant(a) < 0.0;
          open.push_back(std::move(part));
          break;
        }
        if (scene.section->caps && cut.outcome == SectionOutcome::kCut) local.open.push_back(object.name);
        if (cut.outcome == SectionOutcome::kCapped) local.capAreas[i] = capArea(cut, object.transform);
        object.mesh = std::make_shared<const Mesh>(std::move(cut.mesh));
        break;
    }
  }
  const std::vector<bool> joint = capJointly(out.objects, open, -glm::normalize(n));
  for (std::size_t k = 0; k < open.size(); ++k) {
    Object& object = out.objects[open[k].object];
    if (joint[k]) {
      ++local.capped;
      local.outcomes[open[k].object] = SectionOutcome::kCapped;
      local.capAreas[open[k].object] = capArea(open[k].cut, object.transform);  // 0 but on the cap's owner
    } else {
      local.open.push_back(object.name);
    }
    object.mesh = std::make_shared<const Mesh>(std::move(open[k].cut.mesh));
  }
  if (scene.section->slice) {
    // Slices of overlapping volumes would be coplanar and z-fight: each lies one step of 10⁻⁴ of
    // the largest box's diagonal deeper than the one before, so the first volume's shows.
    double step = 0.0;
    for (const Volume& volume : scene.volumes)
      if (volume.grid) step = std::max(step, 1e-4 * glm::length(volume.bounds().max - volume.bounds().min));
    for (std::size_t v = 0; v < scene.volumes.size(); ++v)
      if (std::optional<Object> slice = volumeSlice(scene, v, world, step * static_cast<double>(v + 1))) {
        out.objects.push_back(std::move(*slice));
        // An entry per part of the result: mfr info read past the end for a slice (a crash).
        local.outcomes.push_back(SectionOutcome::kKept);
        local.capAreas.push_back(0.0);
        ++local.slices;
      }
  }
  if (out.triangleCount() == 0 && !out.hasVisibleVolume())
    throw Error("section plane", "cuts away every visible surface of scene '" + scene.name + "'");
  if (report) *report = std::move(local);
  return out;
}

std::vector<std::string> sectionNotes(const SectionPlane& plane, const SectionReport& report) {
  std::vector<std::string> notes;
  if (plane.slice && report.slices == 0)
    notes.emplace_back("section: the plane misses every volume's box, so there is no slice");
  if (!report.open.empty()) {
    std::string names;
    for (std::size_t i = 0; i < report.open.size() && i < 5; ++i) names += (i ? ", " : "") + report.open[i];
    if (report.open.size() > 5) names += ", …";
    notes.push_back("section: " + std::to_string(report.open.size()) + " of " + std::to_string(report.cut) +
                    " cut parts have no cap (not closed surfaces): " + names);
  }
  return notes;
}

SectionPlane parseSectionPlane(const std::string& textIn, const std::string& what) {
  std::string plane = textIn;
  SectionPlane section;
  if (const std::size_t colon = textIn.find(':'); colon != std::string::npos) {
    const std::string suffixes = textIn.substr(colon + 1);
    if (suffixes.empty()) throw Error(what, "the suffixes are :nocaps and :slice (nothing after ':')");
    for (const std::string& suffix : text::splitList(suffixes, ':')) {
      if ((suffix == "nocaps" && !section.caps) || (suffix == "slice" && section.slice))
        throw Error(what, ":" + suffix + " is given twice");
      if (suffix == "nocaps")
        section.caps = false;
      else if (suffix == "slice")
        section.slice = true;
      else
        throw Error(what, "the suffixes are :nocaps and :slice");
    }
    plane = textIn.substr(0, colon);
  }
  if (const std::size_t eq = plane.find('='); eq != std::string::npos) {
    const std::string axis = plane.substr(0, eq);
    static const char* const kAxes[] = {"x", "y", "z", "-x", "-y", "-z"};
    int index = -1;
    for (int a = 0; a < 6; ++a)
      if (axis == kAxes[a]) index = a;
    const std::optional<double> value = text::parseNumber(plane.substr(eq + 1));
    if (index < 0 || !value) throw Error(what, "expected AXIS=VALUE with AXIS one of x, y, z, -x, -y, -z and a number");
    section.normal = glm::dvec3(0.0);
    section.normal[index % 3] = index < 3 ? 1.0 : -1.0;
    section.point = glm::dvec3(0.0);
    section.point[index % 3] = *value;
    return section;
  }
  const auto pointAndNormal = text::parseTwoVectors<glm::dvec3>(plane);
  if (!pointAndNormal) throw Error(what, "expected AXIS=VALUE or six numbers px,py,pz,nx,ny,nz (or none)");
  section.point = pointAndNormal->first;
  section.normal = pointAndNormal->second;
  if (!(glm::length(section.normal) > 0.0)) throw Error(what, "the normal must not be zero");
  return section;
}

}  // namespace mfr
