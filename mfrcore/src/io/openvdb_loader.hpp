#pragma once
// OpenVDB files (.vdb, private to mfrcore/io), read with the OpenVDB library: a sparse float or
// double grid — a fog volume's density, a level set's signed distance — made dense over the
// bounding box of its active voxels (inactive voxels inside it take their background or tile
// value, as OpenVDB's own accessors give them), placed in the world by the grid's linear transform.
#include <filesystem>
#include <string>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr::io {

// Reads the grid named `field`; with none given, the grid named "density" if the file has one, else
// its first float or double grid, else the magnitude of its first vector grid. The name is the
// grid's, the transfer function left empty; field and fields (the grids it could read) are set.
// Grids sharing a name are fields "name", "name[1]", … as OpenVDB names them. Checks the dense size
// against VolumeGrid's limits before allocating. OpenVDB's own log messages, and a line for each
// shared name, go to `notes` (none: OpenVDB's messages to stderr). Throws mfr::Error(name, reason),
// FieldNotFound, LoadCancelled.
Volume readOpenVdb(const std::filesystem::path& path, const std::string& name, const std::string& field,
                   const LoadProgress& progress, std::vector<std::string>* notes);

}  // namespace mfr::io
