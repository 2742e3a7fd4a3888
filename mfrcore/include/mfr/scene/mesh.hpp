#pragma once
// Triangle meshes as every loader produces them and every renderer consumes them.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mfr {

struct Bounds {
  glm::dvec3 min{1e300};
  glm::dvec3 max{-1e300};
  [[nodiscard]] bool valid() const { return min.x <= max.x && min.y <= max.y && min.z <= max.z; }
  void extend(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Bounds& b) {
    if (b.valid()) {
      extend(b.min);
      extend(b.max);
    }
  }
  // Corner i of 8: bit 0 picks max.x over min.x, bit 1 max.y, bit 2 max.z.
  [[nodiscard]] glm::dvec3 corner(int i) const {
    return {(i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z};
  }
  [[nodiscard]] glm::dvec3 center() const { return 0.5 * (min + max); }
  [[nodiscard]] double radius() const { return 0.5 * glm::length(max - min); }
};

// A named data array of the file a mesh was read from (VTK point or cell data): `components` values
// per tuple, one tuple per position (point data) or per triangle, in index order (cell data).
struct MeshField {
  std::string name;
  bool cellData = false;
  int components = 1;
  std::vector<float> values;
  bool operator==(const MeshField&) const = default;
};

// Indexed triangle mesh in object space. normals always has one entry per position (loaders
// compute them when the file has none); colors is empty or one RGBA per position, multiplied
// with the object's material colour (unless the material sets vertexColors false).
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec4> colors;
  std::vector<std::uint32_t> indices;  // 3 per triangle
  // The file's data arrays, in file order (point data, then cell data); what colorByField
  // (scene/color_map.hpp) can colour the surface by.
  std::vector<MeshField> fields;
  // Empty, or one value per position: the field a material's FieldColors maps to colours
  // (set by colorByField; interpolated across each triangle, then mapped, by both renderers).
  std::vector<float> scalars;

  [[nodiscard]] std::size_t triangleCount() const { return indices.size() / 3; }
  [[nodiscard]] Bounds bounds() const;
  // Throws mfr::Error(name, reason) when indices are out of range, sizes disagree, coordinates
  // are not finite or there are no triangles.
  void validate(const std::string& name) const;
  // Area-weighted smooth normals from the triangles (replaces normals).
  void computeSmoothNormals();
};

}  // namespace mfr
