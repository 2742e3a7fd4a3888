#pragma once
// assimp-backed loading (private to mfrcore/io): glTF/GLB and the other formats assimp reads,
// one Object per (node, mesh) with the node's accumulated transform and its material colour.
#include <filesystem>
#include <string>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::io {

// Reads `path`, or `contents` (decompressed bytes; `extension` such as ".glb" tells assimp the
// format) when not null. Reports assimp's import progress, then each mesh converted. Throws
// mfr::Error(name, reason), or LoadCancelled.
std::vector<Object> readWithAssimp(const std::filesystem::path& path, const std::string* contents,
                                   const std::string& extension, const std::string& name,
                                   const LoadProgress& progress = {});

// Lower-case extensions with dot that assimp imports, less those other loaders own or that hold
// no meshes.
std::vector<std::string> assimpExtensions();

}  // namespace mfr::io
