#pragma once
// STEP (ISO 10303-21: .step, .stp) loading with Open CASCADE (private to mfrcore/io): the
// assembly tree walked into one Object per part instance, named from the products and coloured
// from the file's styles. Open CASCADE's headers stay in step_loader.cpp.
#include <filesystem>
#include <string>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::io {

// Reads `path`, or `contents` (decompressed bytes) when not null. `stem` names a part that the
// file leaves unnamed. Reports reading, transfer and each part meshed. Faces the file defines but
// Open CASCADE could not read or mesh are a line in `notes` (when not null). Runs Open CASCADE in a
// child process (child_process.hpp). Throws mfr::Error(name, reason), or LoadCancelled.
std::vector<Object> readStep(const std::filesystem::path& path, const std::string* contents, const std::string& stem,
                             const std::string& name, const LoadProgress& progress = {},
                             std::vector<std::string>* notes = nullptr);

// The linear meshing tolerance as a share of the model's bounding-box diagonal, and the angular
// one in radians (documented in docs/architecture.md, Loaders).
constexpr double kStepRelativeDeflection = 1e-3;
constexpr double kStepAngularDeflection = 20.0 * 3.14159265358979323846 / 180.0;  // 20°

}  // namespace mfr::io
