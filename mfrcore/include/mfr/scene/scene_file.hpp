#pragma once
// The .mfrscene JSON format (docs/scene-format.md).
#include <filesystem>
#include <string>

#include "mfr/scene/scene.hpp"

namespace mfr {

// Parses .mfrscene text; file paths inside resolve relative to baseDir. name is used in messages.
Scene parseSceneFile(const std::string& json, const std::filesystem::path& baseDir, const std::string& name);
Scene readSceneFile(const std::filesystem::path& path);

}  // namespace mfr
