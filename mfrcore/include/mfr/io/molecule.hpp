#pragma once
// A molecule's atoms and bonds as mfr draws them (the model behind loadModel's molecule parts):
// for `mfr info`, and for checking the bonds against other programs'.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mfr {

struct MoleculeAtom {
  int serial = 0;        // the file's atom serial number (PDB columns 7–11, mmCIF _atom_site.id)
  int atomicNumber = 0;  // 0: unknown element; deuterium counts as hydrogen (1)
  glm::dvec3 position{0.0};
  std::size_t part = 0;  // index into MoleculeStructure::parts
};

using Bond = std::array<std::uint32_t, 2>;  // indices of two atoms, the smaller first

struct MoleculeStructure {
  std::vector<std::string> parts;   // "chain A", …, then "ligands" and "water" when there are any
  std::vector<MoleculeAtom> atoms;  // the atoms drawn: part after part, in file order within each
  std::vector<Bond> bonds;          // perceiveBonds(atoms), ascending
  std::size_t models = 1;           // models in the file; only the first is drawn
};

// The first model of a PDB or mmCIF file (also .gz), as loadModel draws it: the first alternative
// location of each atom, parts as loadModel names them. Throws mfr::Error(path, reason) as
// loadModel does.
MoleculeStructure readMoleculeStructure(const std::filesystem::path& path);

// Covalent bonds from distances alone, the rule of Open Babel's ConnectTheDots and Jmol (the Blue
// Obelisk's rebondFrom3DCoordinates): atoms a and b are bonded when 0.4 Å < |a − b| <
// r_a + r_b + 0.45 Å, r the covalent radius (Cordero et al. 2008, as gemmi tabulates it); then,
// while an atom has more bonds than its element can make (hydrogen 1; see the table in the
// source) or two of its bonds meet at less than 45°, its longest bond is dropped — for hydrogen a
// bond to another hydrogen first. Returns each bond once, ascending.
std::vector<Bond> perceiveBonds(const std::vector<MoleculeAtom>& atoms);

}  // namespace mfr
