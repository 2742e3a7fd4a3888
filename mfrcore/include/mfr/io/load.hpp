#pragma once
// Loading files into scenes. Model files become one object per part (mesh + node transform +
// material colour); .mfrscene files are parsed by scene/scene_file.
#include <filesystem>
#include <string>
#include <vector>

#include "mfr/scene/scene.hpp"

namespace mfr {

// Loads a model file — STL, PLY (also .ply.gz), OBJ, OFF, VTP, VTK legacy, glTF/GLB and the other
// formats assimp reads — into parts. Throws mfr::Error(path, reason) for a missing, unreadable,
// truncated, corrupt or unsupported file, or one with no triangles.
std::vector<Object> loadModel(const std::filesystem::path& path);

// File extensions loadModel accepts (lower case, with dot; ".ply.gz" included).
std::vector<std::string> supportedModelExtensions();

// A scene from any supported file: .mfrscene → the scene it describes; a model → its parts with
// a default view fitted to them. Throws mfr::Error naming the file.
Scene loadScene(const std::filesystem::path& path);

}  // namespace mfr
