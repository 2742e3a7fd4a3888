#pragma once
// Molecular structures (private to mfrcore/io): PDB and mmCIF read with gemmi, drawn space-filling
// (CPK: one van der Waals sphere per atom, coloured by element), as sticks, balls and sticks, or
// solvent-excluded surfaces.
#include <cstddef>
#include <string>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::io {

enum class MoleculeFormat { Pdb, Mmcif };

// Reads `contents` (a whole PDB or mmCIF file, already decompressed): the first model, the first
// alternative location of every atom, hydrogens kept. One part per polymer chain ("chain A", in
// file order), then "ligands" (every other non-water residue) and "water", each drawn in every
// representation of `style` — one mesh per part and representation, named "chain A sticks" when
// there are several — with per-vertex element colours and a white material. Reports progress
// after parsing and per part; throws mfr::Error(name, reason) or LoadCancelled. A representation
// drawn on no part while others are drawn is no error: `notes`, when given, gets a line saying so.
std::vector<Object> readMolecule(const std::string& contents, MoleculeFormat format, const std::string& name,
                                 const MoleculeStyle& style = {}, const LoadProgress& progress = {},
                                 std::vector<std::string>* notes = nullptr);

// The atoms readMolecule draws and their bonds.
MoleculeStructure readMoleculeStructure(const std::string& contents, MoleculeFormat format, const std::string& name);

// The tessellation rule: the icosphere subdivision level (0, 1 or 2: 20, 80 or 320 triangles per
// sphere) for a structure of `atoms` atoms — the finest that keeps the whole structure within
// kMoleculeTriangleCap triangles, and level 0 beyond that.
constexpr std::size_t kMoleculeTriangleCap = 2'000'000;
int sphereSubdivisionLevel(std::size_t atoms);

}  // namespace mfr::io
