// Consistent winding and feature-edge splitting by vtkPolyDataNormals' rules, over an edge map
// (see the header for why not VTK's own filter).
#include "mfr/scene/feature_normals.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace mfr {
namespace {

constexpr std::uint32_t kNoEdge = 0xffffffffU;

// The triangles using each edge: a group of distinct triangle ids, in increasing order.
struct EdgeMap {
  // Per corner slot 3t + j: the group of the edge from corner j to corner j + 1 of triangle t as
  // the input winds it; kNoEdge where both corners are one vertex.
  std::vector<std::uint32_t> groupOfSlot;
  std::vector<std::uint32_t> start;  // group g holds members[start[g] .. start[g + 1])
  std::vector<std::uint32_t> members;

  [[nodiscard]] std::uint32_t size(std::uint32_t g) const { return start[g + 1] - start[g]; }
};

std::size_t nextCorner(std::size_t slot) {
  return slot - slot % 3 + (slot % 3 + 1) % 3;
}

EdgeMap buildEdgeMap(const std::vector<std::uint32_t>& indices) {
  struct Use {
    std::uint64_t key;  // the edge's vertices, lower one in the high word
    std::uint32_t slot;
  };
  std::vector<Use> uses;
  uses.reserve(indices.size());
  for (std::size_t s = 0; s < indices.size(); ++s) {
    const std::uint32_t a = indices[s], b = indices[nextCorner(s)];
    if (a == b) continue;
    uses.push_back(
        {(static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b), static_cast<std::uint32_t>(s)});
  }
  // Slots in increasing order within an edge are triangles in increasing order, as VTK lists them.
  std::sort(uses.begin(), uses.end(),
            [](const Use& x, const Use& y) { return x.key != y.key ? x.key < y.key : x.slot < y.slot; });
  EdgeMap map;
  map.groupOfSlot.assign(indices.size(), kNoEdge);
  map.members.reserve(uses.size());
  for (std::size_t i = 0; i < uses.size(); ++i) {
    if (i == 0 || uses[i].key != uses[i - 1].key) map.start.push_back(static_cast<std::uint32_t>(map.members.size()));
    map.groupOfSlot[uses[i].slot] = static_cast<std::uint32_t>(map.start.size() - 1);
    const std::uint32_t triangle = uses[i].slot / 3;
    // A triangle that repeats a vertex uses one edge twice; it is one neighbour.
    if (map.members.size() == map.start.back() || map.members.back() != triangle) map.members.push_back(triangle);
  }
  map.start.push_back(static_cast<std::uint32_t>(map.members.size()));
  return map;
}

}  // namespace

FeatureSplit orientAndSplitAtFeatures(const std::vector<glm::dvec3>& positions, std::vector<std::uint32_t> indices,
                                      double featureAngleDegrees, bool majorityWinding) {
  FeatureSplit out;
  // Corner slots, edge groups and vertex ids are 32-bit (as Mesh::indices are).
  if (indices.size() >= std::numeric_limits<std::uint32_t>::max() ||
      positions.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("orientAndSplitAtFeatures: more than 2^32 - 1 corners or vertices");
  const std::size_t triangles = indices.size() / 3;
  indices.resize(3 * triangles);
  const std::vector<std::uint32_t> input = indices;
  const EdgeMap edges = buildEdgeMap(input);
  // The group of the edge {p, q} of triangle t (whose corners are the input's, in either winding).
  const auto groupOf = [&](std::size_t t, std::uint32_t p, std::uint32_t q) {
    for (std::size_t k = 3 * t; k < 3 * t + 3; ++k) {
      const std::uint32_t a = input[k], b = input[nextCorner(k)];
      if ((a == p && b == q) || (a == q && b == p)) return edges.groupOfSlot[k];
    }
    return kNoEdge;
  };

  // Winding: breadth-first waves from each triangle not yet reached. Once one triangle has looked
  // across an edge, every triangle of that edge is reached, so each edge is looked across once:
  // linear even where thousands of triangles share an edge. With majorityWinding each connected
  // region then keeps the winding most of its triangles have in the file, not its first
  // triangle's: one reversed triangle first in a file turned the whole part inside out.
  {
    std::vector<char> reached(triangles, 0);
    std::vector<char> crossed(edges.start.size() - 1, 0);
    std::vector<std::uint32_t> wave, next, region;
    for (std::size_t seed = 0; seed < triangles; ++seed) {
      if (reached[seed] != 0) continue;
      reached[seed] = 1;
      wave.assign(1, static_cast<std::uint32_t>(seed));
      region.assign(1, static_cast<std::uint32_t>(seed));
      std::size_t turned = 0;  // of the region's triangles, reversed to match the seed
      while (!wave.empty()) {
        next.clear();
        for (const std::uint32_t c : wave)
          for (std::size_t j = 0; j < 3; ++j) {
            const std::uint32_t p = indices[3 * c + j], q = indices[3 * c + (j + 1) % 3];
            const std::uint32_t g = groupOf(c, p, q);
            if (g == kNoEdge || crossed[g] != 0) continue;
            crossed[g] = 1;
            for (std::uint32_t m = edges.start[g]; m < edges.start[g + 1]; ++m) {
              const std::uint32_t t = edges.members[m];
              if (reached[t] != 0) continue;
              // Consistent: the neighbour runs the shared edge from q to p.
              std::size_t l = 0;
              while (l < 2 && indices[3 * t + l] != q) ++l;
              if (indices[3 * t + (l + 1) % 3] != p) {
                std::swap(indices[3 * t], indices[3 * t + 2]);
                ++turned;
              }
              reached[t] = 1;
              next.push_back(t);
              region.push_back(t);
            }
          }
        std::swap(wave, next);
      }
      if (majorityWinding && 2 * turned > region.size()) {  // the seed was in the minority: turn all over
        for (const std::uint32_t t : region) std::swap(indices[3 * t], indices[3 * t + 2]);
        turned = region.size() - turned;
      }
      out.reversed += turned;
    }
  }

  // Unit triangle normals as VTK makes them: (c − b) × (a − b) in double, kept in single precision
  // (the choice of corner decides which nearly collinear triangles get a zero normal and which a
  // unit one of rounding noise).
  std::vector<glm::vec3> faceNormals(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    const glm::dvec3& b = positions[indices[3 * t + 1]];
    const glm::dvec3 n = glm::cross(positions[indices[3 * t + 2]] - b, positions[indices[3 * t]] - b);
    const double length = glm::length(n);
    faceNormals[t] = glm::vec3(length > 0.0 ? n / length : n);
  }

  // Splitting: the triangles around each vertex, in increasing order, each listed once.
  const std::size_t vertices = positions.size();
  std::vector<std::uint32_t> cellStart(vertices + 1, 0);
  const auto repeats = [&](std::size_t k) {
    return (k % 3 >= 1 && input[k] == input[k - 1]) || (k % 3 == 2 && input[k] == input[k - 2]);
  };
  for (std::size_t k = 0; k < input.size(); ++k)
    if (!repeats(k)) ++cellStart[input[k] + 1];
  for (std::size_t v = 0; v < vertices; ++v) cellStart[v + 1] += cellStart[v];
  std::vector<std::uint32_t> cells(cellStart[vertices]);
  {
    std::vector<std::uint32_t> fill(cellStart.begin(), cellStart.end() - 1);
    for (std::size_t k = 0; k < input.size(); ++k)
      if (!repeats(k)) cells[fill[input[k]]++] = static_cast<std::uint32_t>(k / 3);
  }

  const double cosFeature = std::cos(featureAngleDegrees * std::numbers::pi / 180.0);
  out.source.resize(vertices);
  for (std::size_t v = 0; v < vertices; ++v) out.source[v] = static_cast<std::uint32_t>(v);
  out.indices = indices;
  std::vector<int> region(triangles, -1);
  std::vector<std::uint32_t> stack;
  for (std::size_t vi = 0; vi < vertices; ++vi) {
    const auto v = static_cast<std::uint32_t>(vi);
    const std::uint32_t* begin = cells.data() + cellStart[v];
    const std::uint32_t* end = cells.data() + cellStart[v + 1];
    if (end - begin <= 1) continue;
    for (const std::uint32_t* c = begin; c != end; ++c) region[*c] = -1;
    int regions = 0;
    for (const std::uint32_t* c = begin; c != end; ++c) {
      if (region[*c] >= 0) continue;
      region[*c] = regions;
      stack.assign(1, *c);
      while (!stack.empty()) {
        const std::uint32_t x = stack.back();
        stack.pop_back();
        for (std::size_t k = 3 * x; k < 3 * x + 3; ++k) {
          const std::uint32_t w = input[k];
          if (w == v) continue;
          const std::uint32_t g = groupOf(x, v, w);
          if (g == kNoEdge || edges.size(g) != 2) continue;  // boundary or non-manifold: a crease
          const std::uint32_t y =
              edges.members[edges.start[g]] == x ? edges.members[edges.start[g] + 1] : edges.members[edges.start[g]];
          // The dot product in double, as VTK takes it (creases of exactly 30° on grid data are
          // decided by it); a NaN normal joins nothing.
          if (region[y] >= 0 || !(glm::dot(glm::dvec3(faceNormals[x]), glm::dvec3(faceNormals[y])) > cosFeature))
            continue;
          region[y] = regions;
          stack.push_back(y);
        }
      }
      ++regions;
    }
    if (regions <= 1) continue;
    // Regions after the first get new vertices, numbered in order after all earlier ones.
    const auto first = static_cast<std::uint32_t>(out.source.size());
    out.source.insert(out.source.end(), static_cast<std::size_t>(regions - 1), v);
    for (const std::uint32_t* c = begin; c != end; ++c)
      if (region[*c] > 0)
        for (std::size_t k = 3 * *c; k < 3 * *c + 3; ++k)
          if (out.indices[k] == v) out.indices[k] = first + static_cast<std::uint32_t>(region[*c] - 1);
  }

  // Vertex normals: the sum of the unit normals of the triangles using the vertex, made unit.
  out.normals.assign(out.source.size(), glm::vec3(0.0f));
  for (std::size_t k = 0; k < out.indices.size(); ++k) out.normals[out.indices[k]] += faceNormals[k / 3];
  for (glm::vec3& n : out.normals)
    if (const float length = glm::length(n); length != 0.0f) n /= length;
  return out;
}

}  // namespace mfr
