#pragma once
// The .mfrscene JSON format (docs/scene-format.md).
#include <filesystem>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

// Parses .mfrscene text; file paths inside resolve relative to baseDir. name is used in messages.
// progress: one equal part per object and per volume (a model or volume file's own progress
// within its part).
Scene parseSceneFile(const std::string& json, const std::filesystem::path& baseDir, const std::string& name,
                     const LoadProgress& progress = {});
Scene readSceneFile(const std::filesystem::path& path, const LoadProgress& progress = {});

// A CSG tree for `scene` from JSON text in the form of a scene file's "csg" value (an object's
// name, or {"union" | "intersection" | "difference": [nodes]}), checked with validateCsg; blank
// text is no tree. Throws mfr::Error("CSG tree", reason) naming the JSON path. The viewer's CSG
// panel edits trees with it.
CsgTree parseCsgText(const std::string& text, const Scene& scene);
// The tree as that JSON text (compact, objects by name); "" for no tree.
std::string csgText(const CsgTree& tree, const Scene& scene);

}  // namespace mfr
