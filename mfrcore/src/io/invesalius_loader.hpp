#pragma once
// InVesalius 3 projects (.inv3, private to mfrcore/io): a gzip-compressed tar of Apple property
// lists and data files — main.plist (the matrix's shape, dtype and spacing, the display window),
// matrix.dat (the CT/MR samples as raw numpy data, x fastest), and per segmented surface a
// surface_N.plist (name, colour, transparency, visibility) with its surface_N.vtp mesh. The
// archive is read with libarchive, the property lists with VTK's XML parser (expat).
#include <filesystem>
#include <string>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::io {

struct InvesaliusProject {
  std::string name;              // the project's own name (main.plist "name"), else the file's
  Volume volume;                 // the matrix in scene units (mm), transfer from the display window
  std::vector<Object> surfaces;  // the segmented surfaces, in the same coordinates as the volume
};

// Reads the project at `path`; surfaces only when withSurfaces. Checks every declared size before
// allocating and the matrix file's size against its shape and dtype. Throws mfr::Error(name,
// reason) for a missing, truncated, corrupt or unsupported project; LoadCancelled.
InvesaliusProject readInvesaliusProject(const std::filesystem::path& path, const std::string& name, bool withSurfaces,
                                        const LoadProgress& progress);

// The project as a scene: the volume, the surfaces and the default views; errors name the file.
Scene loadInvesaliusScene(const std::filesystem::path& path, const LoadProgress& progress);

}  // namespace mfr::io
