// Image-space CSG: the tree's primitives and postfix program, the per-list classification (the
// rule shaders/ops/csg.glsl implements) and the checks a scene's tree must pass before drawing.
#include "mfr/scene/csg.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {
namespace {

static_assert(static_cast<std::uint32_t>(CsgNode::Op::Primitive) == MFR_CSG_PRIMITIVE);
static_assert(static_cast<std::uint32_t>(CsgNode::Op::Union) == MFR_CSG_UNION);
static_assert(static_cast<std::uint32_t>(CsgNode::Op::Intersection) == MFR_CSG_INTERSECTION);
static_assert(static_cast<std::uint32_t>(CsgNode::Op::Difference) == MFR_CSG_DIFFERENCE);

void collectPrimitives(const CsgNode& node, std::vector<std::uint32_t>& out) {
  if (node.op == CsgNode::Op::Primitive) {
    if (std::find(out.begin(), out.end(), node.object) == out.end()) out.push_back(node.object);
    return;
  }
  for (const CsgNode& child : node.children) collectPrimitives(child, out);
}

// Postfix words of `node`; an n-ary operator becomes a left-deep chain: a b op c op …
void emit(const CsgNode& node, const std::vector<std::uint32_t>& primitives, std::vector<std::uint32_t>& out) {
  if (node.op == CsgNode::Op::Primitive) {
    const auto bit =
        static_cast<std::uint32_t>(std::find(primitives.begin(), primitives.end(), node.object) - primitives.begin());
    out.push_back(MFR_CSG_PRIMITIVE | bit << 8);
    return;
  }
  for (std::size_t i = 0; i < node.children.size(); ++i) {
    emit(node.children[i], primitives, out);
    if (i > 0) out.push_back(static_cast<std::uint32_t>(node.op));
  }
}

[[noreturn]] void malformed() {
  throw Error("CSG program", "malformed (validate the tree first)");
}

// Runs a postfix program on a bool stack (`stack` is scratch space, reused between calls).
bool evaluate(const std::vector<std::uint32_t>& program, std::uint32_t insideMask, std::vector<char>& stack) {
  stack.clear();
  for (const std::uint32_t word : program) {
    const std::uint32_t op = word & 0xffu;
    if (op == MFR_CSG_PRIMITIVE) {
      const std::uint32_t bit = (word >> 8) & 0xffu;
      stack.push_back(bit < 32 && ((insideMask >> bit) & 1u) != 0 ? 1 : 0);
      continue;
    }
    if (stack.size() < 2) malformed();
    const bool b = stack.back() != 0;
    stack.pop_back();
    const bool a = stack.back() != 0;
    bool r = false;
    switch (op) {
      case MFR_CSG_UNION:
        r = a || b;
        break;
      case MFR_CSG_INTERSECTION:
        r = a && b;
        break;
      case MFR_CSG_DIFFERENCE:
        r = a && !b;
        break;
      default:
        malformed();
    }
    stack.back() = r ? 1 : 0;
  }
  if (stack.size() != 1) malformed();
  return stack.back() != 0;
}

std::string opName(CsgNode::Op op) {
  switch (op) {
    case CsgNode::Op::Primitive:
      return "primitive";
    case CsgNode::Op::Union:
      return "union";
    case CsgNode::Op::Intersection:
      return "intersection";
    case CsgNode::Op::Difference:
      return "difference";
  }
  return "operator " + std::to_string(static_cast<std::uint32_t>(op));
}

void checkNode(const Scene& scene, const CsgNode& node, const std::string& where) {
  switch (node.op) {
    case CsgNode::Op::Primitive:
      if (node.object >= scene.objects.size())
        throw Error(where, "CSG primitive refers to object " + std::to_string(node.object) + ", but the scene has " +
                               std::to_string(scene.objects.size()) + " objects");
      if (!node.children.empty())
        throw Error(where, "CSG primitive (object '" + scene.objects[node.object].name + "') has operands");
      return;
    case CsgNode::Op::Union:
    case CsgNode::Op::Intersection:
    case CsgNode::Op::Difference:
      if (node.children.size() < 2)
        throw Error(where, "CSG " + opName(node.op) + " with " + std::to_string(node.children.size()) +
                               " operand(s) (needs at least 2)");
      for (const CsgNode& child : node.children) checkNode(scene, child, where);
      return;
  }
  throw Error(where, "unknown CSG " + opName(node.op));
}

// Maps each vertex to a representative: vertices closer than a millionth of the mesh's largest
// extent (per coordinate) are merged, transitively. Exact coincidence is not enough: the
// generated sphere, cylinder and torus compute their seam and pole vertices twice with
// trigonometry, which differs in the last bits (sin 2π ≠ 0).
std::vector<std::uint32_t> weldVertices(const std::vector<glm::vec3>& positions) {
  const std::size_t n = positions.size();
  std::vector<std::uint32_t> parent(n);
  for (std::size_t i = 0; i < n; ++i) parent[i] = static_cast<std::uint32_t>(i);
  const auto find = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto unite = [&](std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };

  Bounds bounds;
  for (const glm::vec3& p : positions) bounds.extend(glm::dvec3(p));
  const glm::dvec3 size = bounds.max - bounds.min;
  const double eps = 1e-6 * std::max({size.x, size.y, size.z});

  // Exact duplicates first (a triangle soup has many), then nearby distinct positions through a
  // grid of cells of side eps: a neighbour within eps lies in one of the 27 cells around.
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(x) | static_cast<std::uint64_t>(y) << 21 | static_cast<std::uint64_t>(z) << 42;
  };
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells;  // distinct positions per cell
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 p(positions[i]);
    // (p − min)/eps ≤ 10⁶ < 2²¹ per axis; cell coordinates are shifted by one so neighbours stay ≥ 0.
    const glm::dvec3 c = eps > 0 ? glm::floor((p - bounds.min) / eps) + 1.0 : glm::dvec3(1.0);
    const auto cx = static_cast<std::int64_t>(c.x), cy = static_cast<std::int64_t>(c.y),
               cz = static_cast<std::int64_t>(c.z);
    bool duplicate = false;
    for (std::int64_t dz = -1; dz <= 1 && !duplicate; ++dz)
      for (std::int64_t dy = -1; dy <= 1 && !duplicate; ++dy)
        for (std::int64_t dx = -1; dx <= 1 && !duplicate; ++dx) {
          const auto it = cells.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells.end()) continue;
          for (const std::uint32_t j : it->second) {
            const glm::dvec3 d = glm::abs(glm::dvec3(positions[j]) - p);
            if (std::max({d.x, d.y, d.z}) > eps) continue;
            unite(static_cast<std::uint32_t>(i), j);
            if (positions[j] == positions[i]) duplicate = true;  // j stands for this position already
          }
        }
    if (!duplicate) cells[key(cx, cy, cz)].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<std::uint32_t> rep(n);
  for (std::size_t i = 0; i < n; ++i) rep[i] = find(static_cast<std::uint32_t>(i));
  return rep;
}

// Edges (after welding) not shared by exactly two triangles of non-zero area; -1 when no
// triangle has a non-zero area.
long long badEdges(const Mesh& mesh) {
  const std::vector<std::uint32_t> rep = weldVertices(mesh.positions);
  std::unordered_map<std::uint64_t, std::uint32_t> uses;
  std::size_t triangles = 0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::array<std::uint32_t, 3> v = {rep[mesh.indices[t]], rep[mesh.indices[t + 1]], rep[mesh.indices[t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
    const glm::dvec3 a(mesh.positions[v[0]]), b(mesh.positions[v[1]]), c(mesh.positions[v[2]]);
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    if (normal.x == 0.0 && normal.y == 0.0 && normal.z == 0.0) continue;  // zero area
    ++triangles;
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t p = v[static_cast<std::size_t>(e)], q = v[static_cast<std::size_t>((e + 1) % 3)];
      ++uses[static_cast<std::uint64_t>(std::min(p, q)) << 32 | std::max(p, q)];
    }
  }
  if (triangles == 0) return -1;
  return std::count_if(uses.begin(), uses.end(), [](const auto& e) { return e.second != 2; });
}

}  // namespace

std::vector<std::uint32_t> CsgTree::primitives() const {
  std::vector<std::uint32_t> out;
  if (root) collectPrimitives(*root, out);
  return out;
}

std::vector<std::uint32_t> CsgTree::program() const {
  std::vector<std::uint32_t> out;
  if (root) emit(*root, primitives(), out);
  return out;
}

bool CsgTree::inside(std::uint32_t insideMask) const {
  if (!root) return false;
  std::vector<char> stack;
  return evaluate(program(), insideMask, stack);
}

std::optional<std::size_t> csgVisibleFragment(const CsgTree& tree, std::span<const Fragment> sorted,
                                              std::uint32_t mirrored) {
  if (sorted.empty()) return std::nullopt;
  const std::vector<std::uint32_t> primitives = tree.primitives();
  const std::vector<std::uint32_t> program = tree.program();
  std::vector<char> stack;
  stack.reserve(program.size());
  std::uint32_t mask = 0;
  bool inside = !program.empty() && evaluate(program, mask, stack);  // every ray starts outside: false
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const Fragment& f = sorted[i];
    const auto it = std::find(primitives.begin(), primitives.end(), f.objectId);
    if (it == primitives.end()) return i;  // an ordinary opaque surface
    const auto bit = static_cast<std::uint32_t>(it - primitives.begin());
    if (bit >= 32) continue;  // beyond MFR_CSG_MAX_PRIMITIVES: validateCsg refuses such trees
    const bool entering = f.frontFacing != (((mirrored >> bit) & 1u) != 0);
    mask = entering ? mask | 1u << bit : mask & ~(1u << bit);
    const bool after = evaluate(program, mask, stack);
    if (!inside && after) return i;
    inside = after;
  }
  return std::nullopt;
}

std::uint32_t csgMirroredPrimitives(const Scene& scene) {
  std::uint32_t mask = 0;
  const std::vector<std::uint32_t> primitives = scene.csg.primitives();
  for (std::size_t i = 0; i < primitives.size() && i < MFR_CSG_MAX_PRIMITIVES; ++i)
    if (primitives[i] < scene.objects.size() &&
        glm::determinant(glm::dmat3(scene.objects[primitives[i]].transform)) < 0.0)
      mask |= 1u << i;
  return mask;
}

void validateCsg(const Scene& scene) {
  if (scene.csg.empty()) return;
  const std::string where = "scene '" + scene.name + "'";
  checkNode(scene, *scene.csg.root, where);
  const std::vector<std::uint32_t> primitives = scene.csg.primitives();
  if (primitives.size() > MFR_CSG_MAX_PRIMITIVES)
    throw Error(where, "CSG tree has " + std::to_string(primitives.size()) + " distinct objects (at most " +
                           std::to_string(MFR_CSG_MAX_PRIMITIVES) + ")");
  const std::vector<std::uint32_t> program = scene.csg.program();
  if (program.size() > MFR_CSG_MAX_PROGRAM)
    throw Error(where, "CSG tree needs " + std::to_string(program.size()) + " program words (at most " +
                           std::to_string(MFR_CSG_MAX_PROGRAM) + ")");
  std::size_t depth = 0, maxDepth = 0;
  for (const std::uint32_t word : program) {
    depth = (word & 0xffu) == MFR_CSG_PRIMITIVE ? depth + 1 : depth - 1;
    maxDepth = std::max(maxDepth, depth);
  }
  if (maxDepth > MFR_CSG_MAX_PRIMITIVES)
    throw Error(where, "CSG program needs a stack of " + std::to_string(maxDepth) + " (at most " +
                           std::to_string(MFR_CSG_MAX_PRIMITIVES) + ")");
  // A section without caps leaves every cut solid open: say so, or the file seems to blame.
  const std::string cutOpen = scene.sectionCut && scene.section && !scene.section->caps
                                  ? "; the section without caps cut it open: CSG needs the caps"
                                  : "";
  for (const std::uint32_t index : primitives) {
    const Object& object = scene.objects[index];
    const std::string name = (cutOpen.empty() ? "" : where + ": ") + "object '" + object.name + "'";
    if (!object.mesh) throw Error(name, "has no mesh (CSG needs a closed solid)");
    object.mesh->validate(name);
    const long long bad = badEdges(*object.mesh);
    if (bad < 0) throw Error(name, "not a closed surface: no triangle of non-zero area (CSG needs solids)" + cutOpen);
    if (bad > 0)
      throw Error(name, "not a closed surface: " + std::to_string(bad) +
                            " edges on the border or shared by more than two triangles (CSG needs solids)" + cutOpen);
  }
}

}  // namespace mfr
