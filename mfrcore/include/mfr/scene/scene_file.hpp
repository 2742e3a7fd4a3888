#pragma once
// The .mfrscene JSON format (docs/scene-format.md).
#include <filesystem>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

// Parses .mfrscene text; file paths inside resolve relative to baseDir. name is used in messages.
// progress: one equal part per object (a model file's own progress within its part).
Scene parseSceneFile(const std::string& json, const std::filesystem::path& baseDir, const std::string& name,
                     const LoadProgress& progress = {});
Scene readSceneFile(const std::filesystem::path& path, const LoadProgress& progress = {});

}  // namespace mfr
