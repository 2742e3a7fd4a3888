#pragma once
// Scalar volume files (private to mfrcore/io): VTK's image readers for .vti, legacy .vtk
// STRUCTURED_POINTS, MetaImage and NRRD, CGAL's ImageIO for INRIMAGE. The public entry points
// (loadVolume, isVolumeFile, supportedVolumeExtensions) are in volume_loader.cpp too.
#include <filesystem>
#include <optional>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr::io {

enum class VolumeFormat { Vti, LegacyVtk, MetaImage, Nrrd, Inrimage };

// The volume format `path` names by its extension (case-insensitive); a .vtk file only when its
// header says DATASET STRUCTURED_POINTS. nullopt: not a volume file.
std::optional<VolumeFormat> volumeFormat(const std::filesystem::path& path);

// Reads the grid, its origin and spacing (and, for a VTK direction matrix, negative spacings or
// an extent not starting at 0, the transform that places it) of a file of that format. The name
// is the file's, the transfer function left empty. Checks the grid size before reading the
// samples. Throws mfr::Error(name, reason), LoadCancelled.
Volume readVolumeWithVtk(VolumeFormat format, const std::filesystem::path& path, const std::string& name,
                         const LoadProgress& progress);
Volume readInrimage(const std::filesystem::path& path, const std::string& name, const LoadProgress& progress);

}  // namespace mfr::io
