#include "mfr/scene/mesh.hpp"

#include <cmath>

#include "mfr/error.hpp"

namespace mfr {

Bounds Mesh::bounds() const {
  Bounds b;
  for (const glm::vec3& p : positions) b.extend(glm::dvec3(p));
  return b;
}

void Mesh::validate(const std::string& name) const {
  if (indices.empty() || positions.empty()) throw Error(name, "no triangles");
  if (indices.size() % 3 != 0) throw Error(name, "index count is not a multiple of 3");
  if (!normals.empty() && normals.size() != positions.size())
    throw Error(name, "normal count differs from vertex count");
  if (!colors.empty() && colors.size() != positions.size()) throw Error(name, "colour count differs from vertex count");
  if (!scalars.empty() && scalars.size() != positions.size())
    throw Error(name, "scalar count differs from vertex count");
  for (const MeshField& f : fields) {
    const std::size_t tuples = f.cellData ? triangleCount() : positions.size();
    if (f.components < 1 || f.values.size() != tuples * static_cast<std::size_t>(f.components))
      throw Error(name, "field '" + f.name + "' has " + std::to_string(f.values.size()) + " values, expected " +
                            std::to_string(tuples) + " tuples of " + std::to_string(f.components));
  }
  for (std::uint32_t i : indices)
    if (i >= positions.size())
      throw Error(name, "vertex index " + std::to_string(i) + " out of range (" + std::to_string(positions.size()) +
                            " vertices)");
  for (const glm::vec3& p : positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(name, "non-finite vertex coordinate");
}

void Mesh::computeSmoothNormals() {
  std::vector<glm::dvec3> acc(positions.size(), glm::dvec3(0.0));
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const glm::dvec3 a(positions[indices[t]]), b(positions[indices[t + 1]]), c(positions[indices[t + 2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);  // length = 2·area: area weighting for free
    for (int k = 0; k < 3; ++k) acc[indices[t + k]] += n;
  }
  normals.resize(positions.size());
  for (std::size_t i = 0; i < acc.size(); ++i) {
    const double len = glm::length(acc[i]);
    normals[i] = len > 0.0 ? glm::vec3(acc[i] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

}  // namespace mfr
