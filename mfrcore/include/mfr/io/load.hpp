#pragma once
// Loading files into scenes. Model files become one object per part (mesh + node transform +
// material colour); .mfrscene files are parsed by scene/scene_file.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
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

// Which of a molecule's parts a representation draws: its polymer chains ("chain A", …), its
// ligands, its water (PyMOL's polymer, organic + inorganic, solvent).
struct MoleculeParts {
  bool polymer = false, ligands = false, water = false;

  static constexpr MoleculeParts all() { return {true, true, true}; }
  // Drawn on some part.
  explicit operator bool() const { return polymer || ligands || water; }
  bool operator==(const MoleculeParts&) const = default;
};

// How a molecule (PDB, mmCIF) is drawn: any combination of these representations, each on all
// parts or on some (PyMOL's `show sticks, organic`), each a part of its own per chain.
struct MoleculeStyle {
  MoleculeParts spheres = MoleculeParts::all();  // space-filling: van der Waals spheres (PyMOL's spheres, CPK)
  MoleculeParts ballAndStick;  // balls of 23 % of the van der Waals radius, sticks of 0.15 Å (Jmol's)
  MoleculeParts sticks;        // bonds as sticks of radius 0.25 Å, joined by spheres (PyMOL's sticks)
  MoleculeParts cartoon;       // each polymer chain's backbone as helices, strands and loops (PyMOL's cartoon)
  MoleculeParts surface;       // the solvent-excluded surface of each part but water (probe 1.4 Å)

  // Some representation on some part.
  [[nodiscard]] bool any() const { return spheres || ballAndStick || sticks || cartoon || surface; }
  // "spheres", "surface,sticks", "cartoon,sticks@ligands": the names in the order spheres,
  // ball-and-stick, sticks, cartoon, surface; one drawn on some parts only is followed by '@' and
  // each of them (polymer, ligands, water), one item each.
  [[nodiscard]] std::string text() const;
  // One or more names separated by ',' or '+', each on all parts or, followed by '@polymer',
  // '@ligands' or '@water', on those (several items of one name add up). Throws
  // mfr::Error(what, reason) for an unknown or missing name or part.
  static MoleculeStyle parse(const std::string& text, const std::string& what);
  bool operator==(const MoleculeStyle&) const = default;
};

// What to read of a file that holds several things.
struct LoadOptions {
  LoadOptions() = default;
  explicit LoadOptions(std::string field_, std::optional<MoleculeStyle> molecule_ = {})
      : field(std::move(field_)), molecule(molecule_) {}

  // Volume files: the point-data array (.vti, legacy .vtk) or grid (.vdb) to read; empty: the
  // default (see loadVolume). Given for any other file, loading fails.
  std::string field;
  // Molecule files: how to draw it; none: space-filling spheres. Given for any other file,
  // loading fails.
  std::optional<MoleculeStyle> molecule;
  // Where loading adds a line, naming the file, for each thing it could not do as asked but that
  // is no error (a molecule representation drawn on no part: `cartoon,sticks` of a structure
  // without a chain to draw a cartoon of); none: not kept.
  std::vector<std::string>* notes = nullptr;
};

// Loads a model file — STL, PLY (also .ply.gz), OBJ, OFF, VTP, VTK legacy, STEP, glTF/GLB and the
// other formats assimp reads — into parts; PDB and mmCIF molecules (also .gz) become spheres, one
// part per chain plus ligands and water. Throws mfr::Error(path, reason) for a missing, unreadable,
// truncated, corrupt or unsupported file, or one with no triangles; LoadCancelled when cancelled.
std::vector<Object> loadModel(const std::filesystem::path& path, const LoadProgress& progress = {});
// The same with options.molecule for a molecule file (options.field must be empty).
std::vector<Object> loadModel(const std::filesystem::path& path, const LoadOptions& options,
                              const LoadProgress& progress = {});

// Whether `path` names a molecule file (.pdb, .ent, .cif, .mmcif, optionally .gz) by its name.
bool isMoleculeFile(const std::filesystem::path& path);

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
// the same views. options.field is for a volume file only, options.molecule for a molecule file. Throws mfr::Error
// naming the file, or LoadCancelled.
Scene loadScene(const std::filesystem::path& path, const LoadProgress& progress = {});
Scene loadScene(const std::filesystem::path& path, const LoadOptions& options, const LoadProgress& progress = {});

}  // namespace mfr
