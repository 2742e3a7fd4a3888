#pragma once
// Scalar volume files (private to mfrcore/io): VTK's image readers for .vti, legacy .vtk
// STRUCTURED_POINTS, MetaImage and NRRD, CGAL's ImageIO for INRIMAGE. The public entry points
// (loadVolume, isVolumeFile, supportedVolumeExtensions) are in volume_loader.cpp too.
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr::io {

enum class VolumeFormat { Vti, LegacyVtk, MetaImage, Nrrd, Inrimage, Invesalius, OpenVdb };

// The volume format `path` names by its extension (case-insensitive); a .vtk file only when its
// header says DATASET STRUCTURED_POINTS. nullopt: not a volume file.
std::optional<VolumeFormat> volumeFormat(const std::filesystem::path& path);

// Reads the grid, its origin and spacing (and, for a VTK direction matrix, negative spacings or
// an extent not starting at 0, the transform that places it) of a file of that format. The name
// is the file's, the transfer function left empty. Checks the grid size before reading the
// samples. Throws mfr::Error(name, reason), LoadCancelled.
// `field`: the point-data array to read (empty: the active scalars, else the first array).
Volume readVolumeWithVtk(VolumeFormat format, const std::filesystem::path& path, const std::string& name,
                         const std::string& field, const LoadProgress& progress);
Volume readInrimage(const std::filesystem::path& path, const std::string& name, const LoadProgress& progress);

// Throws mfr::Error(name, reason) unless a declared grid of d points per axis is within
// VolumeGrid's limits (≥ 2 and ≤ 2048 per axis, ≤ 2^30 points); called before allocating.
void checkDims(const std::array<std::int64_t, 3>& d, const std::string& name);

// Reports progress every few million samples of a conversion loop.
inline constexpr std::size_t kProgressChunk = std::size_t{1} << 22;

// n samples of type T, `stride` bytes apart (interlaced components: the first one), as floats;
// progress from 0.7 to 0.95 of the load.
template <typename T>
void convertSamples(const void* data, std::size_t n, std::size_t stride, std::vector<float>& out,
                    const LoadProgress& progress) {
  out.resize(n);
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, bytes + i * stride, sizeof(T));
    out[i] = static_cast<float>(v);
    if ((i + 1) % kProgressChunk == 0) progress.step(0.7 + 0.25 * static_cast<double>(i + 1) / static_cast<double>(n));
  }
}

}  // namespace mfr::io
