#pragma once
// Loading files into scenes. Model files become one object per part (mesh + node transform +
// material colour); .mfrscene files are parsed by scene/scene_file.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

// Thrown by a loader whose LoadProgress::report returned false.
class LoadCancelled : public Error {
 public:
  LoadCancelled() : Error("loading cancelled") {}
};

// Progress of one load, reported on the loading thread: report(fraction) with fraction in [0, 1],
// non-decreasing, 1 when done. Returning false cancels: the loader stops at that report and
// throws LoadCancelled. Loaders report at the start and end of every file, per object and per
// volume of a .mfrscene, per mesh of an assimp scene (and assimp's own import progress), and for
// STEP after parsing, during the transfer and per part meshed.
struct LoadProgress {
  std::function<bool(double fraction)> report;  // empty: no reporting, never cancelled
  double begin = 0.0, end = 1.0;                // the part of the whole load this one covers

  // Reports `fraction` of this part; throws LoadCancelled when report returns false.
  void step(double fraction) const;
  // Like step, but returns false instead of throwing (for callbacks that must not throw).
  [[nodiscard]] bool tryStep(double fraction) const;
  // The part [from, to] (fractions of this one) as a progress of its own.
  [[nodiscard]] LoadProgress part(double from, double to) const;
};

// What to read of a file that holds several things.
struct LoadOptions {
  // Volume files: the point-data array (.vti, legacy .vtk) or grid (.vdb) to read; empty: the
  // default (see loadVolume). Given for any other file, loading fails.
  std::string field;
};

// Loads a model file — STL, PLY (also .ply.gz), OBJ, OFF, VTP, VTK legacy, STEP, glTF/GLB and the
// other formats assimp reads — into parts; PDB and mmCIF molecules (also .gz) become spheres, one
// part per chain plus ligands and water. Throws mfr::Error(path, reason) for a missing, unreadable,
// truncated, corrupt or unsupported file, or one with no triangles; LoadCancelled when cancelled.
std::vector<Object> loadModel(const std::filesystem::path& path, const LoadProgress& progress = {});

// File extensions loadModel accepts (lower case, with dot; ".ply.gz" included).
std::vector<std::string> supportedModelExtensions();

// Loads a scalar volume — VTK image data (.vti), legacy VTK STRUCTURED_POINTS (.vtk), MetaImage
// (.mhd/.mha), NRRD (.nrrd/.nhdr) and INRIMAGE (.inr, .inr.gz) — named after the file, with its
// origin and spacing, the first component of its first point-data scalar array as float, and
// defaultTransfer(). options.field picks another array (or, in a .vdb file, another grid);
// Volume::field and Volume::fields say which was read and which there are. Throws
// mfr::Error(path, reason) for a missing, unreadable, truncated, corrupt, too large or unsupported
// file, FieldNotFound for a field the file does not have; LoadCancelled when cancelled.
Volume loadVolume(const std::filesystem::path& path, const LoadProgress& progress = {});
Volume loadVolume(const std::filesystem::path& path, const LoadOptions& options, const LoadProgress& progress = {});

// File extensions loadVolume accepts (lower case, with dot; ".inr.gz" included). ".vtk" is both a
// model and a volume extension: see isVolumeFile.
std::vector<std::string> supportedVolumeExtensions();

// Whether `path` names a volume by its extension; a legacy .vtk file is a volume when its header
// says DATASET STRUCTURED_POINTS (else it is a model for loadModel).
bool isVolumeFile(const std::filesystem::path& path);

// A scene from any supported file: .mfrscene → the scene it describes; a model → its parts with
// default views ("front", "iso") fitted to them; a volume file → a scene of that one volume with
// the same views. options.field is for a volume file only. Throws mfr::Error naming the file, or
// LoadCancelled.
Scene loadScene(const std::filesystem::path& path, const LoadProgress& progress = {});
Scene loadScene(const std::filesystem::path& path, const LoadOptions& options, const LoadProgress& progress = {});

}  // namespace mfr
