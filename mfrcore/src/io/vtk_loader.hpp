#pragma once
// VTK-backed loading (private to mfrcore/io): the STL and VTP readers, plus the
// triangulation and feature-angle normals that every loader shares, so that all formats come out
// with the same tessellation and shading rules.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/mesh.hpp"

namespace mfr::io {

// Creases sharper than this get split normals (crisp CAD edges); smoother ones are averaged.
inline constexpr double kFeatureAngleDegrees = 30.0;

// Polygons of any size as the simple parsers (PLY, OFF) produce them.
struct PolygonSoup {
  std::vector<glm::vec3> points;
  std::vector<glm::vec3> normals;         // empty or one per point
  std::vector<glm::vec4> colors;          // empty or one RGBA in [0,1] per point
  std::vector<std::uint32_t> offsets{0};  // polygon i is ids[offsets[i] .. offsets[i+1])
  std::vector<std::uint32_t> ids;
  // The file's data arrays (Mesh::fields): point fields one tuple per point, cell fields one per
  // polygon of the soup (MeshField::cellData marks them).
  std::vector<MeshField> fields;

  void addPolygon(const std::uint32_t* first, std::size_t count) {
    ids.insert(ids.end(), first, first + count);
    offsets.push_back(static_cast<std::uint32_t>(ids.size()));
  }
  [[nodiscard]] std::size_t polygonCount() const { return offsets.size() - 1; }
};

// Checks ids and coordinates, triangulates (concave polygons too) and, when the soup carries no
// normals, computes feature-angle normals. Throws mfr::Error(name, reason).
Mesh meshFromSoup(const PolygonSoup& soup, const std::string& name);

// Replaces mesh.normals by feature-angle normals; vertices on creases are split, so positions,
// colors and indices change too.
void computeFeatureNormals(Mesh& mesh, const std::string& name);

// Collects the VTK messages of one read on this thread (RAII: restores the previous collector).
// VTK prints through a global output window; the first VtkMessages installs one that prints
// nothing, so a failed read names VTK's reason in its one-line mfr::Error instead.
class VtkMessages {
 public:
  struct Message {
    bool error = false;  // else a warning
    std::string text;
  };

  VtkMessages();
  ~VtkMessages();
  VtkMessages(const VtkMessages&) = delete;
  VtkMessages& operator=(const VtkMessages&) = delete;

  [[nodiscard]] bool hasError() const;
  [[nodiscard]] bool hasWarning() const;
  // The most specific message: the first error (else warning) that is not the executive's
  // generic "returned failure for request" dump; "" when there is none.
  [[nodiscard]] std::string reason() const;
  void clear() { messages_.clear(); }

 private:
  std::vector<Message> messages_;
  std::vector<Message>* previous_;
};

// STL and VTP; OBJ and legacy .vtk have parsers of their own (obj_loader, vtk_legacy_loader)
// because VTK's readers crash on malformed input.
enum class VtkFormat { Stl, Vtp };

// Reads `path` with VTK, or `contents` (already decompressed bytes of that file) when not null.
// Throws mfr::Error(name, reason); VTK's own messages never reach stderr.
Mesh readWithVtk(VtkFormat format, const std::filesystem::path& path, const std::string* contents,
                 const std::string& name);

}  // namespace mfr::io
