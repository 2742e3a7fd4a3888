#pragma once
// A molecule's atoms and bonds as mfr draws them (the model behind loadModel's molecule parts):
// for `mfr info`, and for checking the bonds against other programs'.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
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

// A residue's secondary structure as a cartoon draws it: DSSP's H (α-helix; its π-helices count
// as helix too) and E (strand of a β-ladder); everything else (3₁₀ helices, turns, bends,
// isolated bridges, coil) is loop.
enum class SecondaryStructure : std::uint8_t { Loop, Helix, Strand };

// DSSP's letter for it: 'H', 'E', or '-' for loop (as mfr info lists them).
constexpr char secondaryStructureLetter(SecondaryStructure s) {
  return s == SecondaryStructure::Helix ? 'H' : s == SecondaryStructure::Strand ? 'E' : '-';
}

// A residue of a polymer chain with the atoms its backbone is traced and assigned by.
struct BackboneResidue {
  std::size_t part = 0;  // index into MoleculeStructure::parts
  std::string chain;     // the file's chain name (PDB column 22, mmCIF auth_asym_id)
  int number = 0;        // sequence number and insertion code (' ' for none)
  char insertion = ' ';
  std::string name;  // residue name, "ALA"
  // Amino acids: the backbone's N, CA, C and O; nucleotides: the phosphorus, and the base atom a
  // cartoon's ladder reaches (N1 of a purine, N3 of a pyrimidine, as PyMOL's). Absent atoms are
  // empty (first alternative location otherwise, as drawn).
  std::optional<glm::dvec3> n, ca, c, o, phosphorus, base;
  SecondaryStructure structure = SecondaryStructure::Loop;
};

struct MoleculeStructure {
  std::vector<std::string> parts;   // "chain A", …, then "ligands" and "water" when there are any
  std::vector<MoleculeAtom> atoms;  // the atoms drawn: part after part, in file order within each
  std::vector<Bond> bonds;          // perceiveBonds(atoms), ascending
  std::size_t models = 1;           // models in the file; only the first is drawn
  // The polymer chains' residues in file order, with their secondary structure: the file's own
  // (PDB HELIX/SHEET records, mmCIF _struct_conf/_struct_sheet_range) when it has any, as PyMOL
  // takes it, otherwise assignSecondaryStructure's.
  std::vector<BackboneResidue> residues;
  bool secondaryStructureFromFile = false;
  // The file has HELIX/SHEET records, but none holds a residue of the structure (chains renamed or
  // residues renumbered after the header was written): DSSP's is drawn instead.
  bool secondaryStructureRecordsUnmatched = false;
};

// The first model of a PDB or mmCIF file (also .gz), as loadModel draws it: the first alternative
// location of each atom, parts as loadModel names them. Throws mfr::Error(path, reason) as
// loadModel does.
MoleculeStructure readMoleculeStructure(const std::filesystem::path& path);

// The chemical symbol of an element ("C", "Se"); "X" for 0 (unknown) and numbers beyond the table.
std::string elementSymbol(int atomicNumber);

// Covalent bonds from distances alone, the rule of Open Babel's ConnectTheDots and Jmol (the Blue
// Obelisk's rebondFrom3DCoordinates): atoms a and b are bonded when 0.4 Å < |a − b| <
// r_a + r_b + 0.45 Å, r the covalent radius (Cordero et al. 2008, as gemmi tabulates it); then,
// while an atom has more bonds than its element can make (hydrogen 1; see the table in the
// source) or two of its bonds meet at less than 45°, its longest bond is dropped — for hydrogen a
// bond to another hydrogen first. Returns each bond once, ascending.
std::vector<Bond> perceiveBonds(const std::vector<MoleculeAtom>& atoms);

// DSSP (Kabsch & Sander 1983, "Dictionary of protein secondary structure", Biopolymers 22:2577),
// as the program mkdssp computes it, reduced to helix and strand: backbone hydrogen bonds by the
// electrostatic energy E = 0.084·332·(1/r_ON + 1/r_CH − 1/r_OH − 1/r_CN) kcal/mol < −0.5 (H placed
// 1 Å from N opposite the previous C=O; each N–H keeps its two best bonds), between residues whose
// Cα are within 9 Å, in any chain; two consecutive 4-turns make an α-helix (5-turns, π-helices,
// count as helix as well, where no 3₁₀ helix, strand or isolated bridge is), ladders of two or
// more β-bridges (joined across bulges) make strands, and α-helix wins over strand. Residues lacking N, CA, C or O take
// part in nothing and are loop; a peptide bond longer than 2.5 Å breaks the chain. Returns one value per residue.
// Throws mfr::Error("secondary structure", reason) for backbones packed denser than any protein.
std::vector<SecondaryStructure> assignSecondaryStructure(const std::vector<BackboneResidue>& residues);

}  // namespace mfr
