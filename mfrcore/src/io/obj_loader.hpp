#pragma once
// Wavefront OBJ parser (private to mfrcore/io). Our own rather than vtkOBJReader: VTK's reader
// crashes on out-of-range texture/normal indices ("f 1//1 2//1 55/1"), reads "nan" or "1x" as 0
// without a word, and ignores materials, which CAD exports use to colour their parts.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "vtk_loader.hpp"

namespace mfr::io {

// The faces of one material (usemtl); a file without materials gives one part.
struct ObjPart {
  std::string material;            // empty when the file names none
  std::optional<glm::vec4> color;  // Kd and d / Tr from the .mtl file, when found
  PolygonSoup soup;                // with normals when every corner of the part has a vn
};

// v (optionally with r g b), vn, f with v, v/vt, v//vn, v/vt/vn and negative indices, usemtl and
// mtllib (read from `directory`; a missing .mtl only loses colours, and says so in `notes`, as does
// a material no library defines). Other statements are ignored. Throws mfr::Error(name, "line N:
// reason").
std::vector<ObjPart> parseObj(std::string_view bytes, const std::filesystem::path& directory, const std::string& name,
                              std::vector<std::string>* notes = nullptr);

}  // namespace mfr::io
