// The molecule loader (PDB, mmCIF, gzip'd or not) on small hand-written structures: parts, atom
// counts, the first model and the first alternative location, sphere geometry and colours, the
// tessellation rule, progress and cancelling; and every kind of bad input as one mfr::Error that
// names the file. The expected numbers are counted by hand from the files written here.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/reference/oracle.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

// One PDB ATOM/HETATM record in the format's fixed columns (name already padded to 4 columns).
std::string atomRecord(const char* record, int serial, const char* name, char altloc, const char* residue, char chain,
                       int seq, double x, double y, double z, const char* element) {
  char line[96];
  std::snprintf(line, sizeof line, "%-6s%5d %-4s%c%3s %c%4d    %8.3f%8.3f%8.3f%6.2f%6.2f          %2s  \n", record,
                serial, name, altloc, residue, chain, seq, x, y, z, 1.0, 20.0, element);
  return line;
}

struct TinyAtom {
  const char* record;
  const char* name;
  char altloc;
  const char* residue;
  char chain;
  int seq;
  const char* element;
  const char* entity;  // mmCIF entity id
};

// Chain A: ALA 1, GLY 2, SER 3 with OG in two alternative locations (A kept); a sulphate and two
// waters in chain A after its TER; chain B: one GLY with its hydrogens.
//   chain A: 5 + 4 + 6 = 15 atoms, chain B: 7, ligands: 5, water: 2 — 29 atoms kept of 30.
const std::vector<TinyAtom>& tinyAtoms() {
  static const std::vector<TinyAtom> atoms = {
      {"ATOM", " N  ", ' ', "ALA", 'A', 1, "N", "1"},     {"ATOM", " CA ", ' ', "ALA", 'A', 1, "C", "1"},
      {"ATOM", " C  ", ' ', "ALA", 'A', 1, "C", "1"},     {"ATOM", " O  ", ' ', "ALA", 'A', 1, "O", "1"},
      {"ATOM", " CB ", ' ', "ALA", 'A', 1, "C", "1"},     {"ATOM", " N  ", ' ', "GLY", 'A', 2, "N", "1"},
      {"ATOM", " CA ", ' ', "GLY", 'A', 2, "C", "1"},     {"ATOM", " C  ", ' ', "GLY", 'A', 2, "C", "1"},
      {"ATOM", " O  ", ' ', "GLY", 'A', 2, "O", "1"},     {"ATOM", " N  ", ' ', "SER", 'A', 3, "N", "1"},
      {"ATOM", " CA ", ' ', "SER", 'A', 3, "C", "1"},     {"ATOM", " C  ", ' ', "SER", 'A', 3, "C", "1"},
      {"ATOM", " O  ", ' ', "SER", 'A', 3, "O", "1"},     {"ATOM", " CB ", ' ', "SER", 'A', 3, "C", "1"},
      {"ATOM", " OG ", 'A', "SER", 'A', 3, "O", "1"},     {"ATOM", " OG ", 'B', "SER", 'A', 3, "O", "1"},
      {"HETATM", " S  ", ' ', "SO4", 'A', 101, "S", "2"}, {"HETATM", " O1 ", ' ', "SO4", 'A', 101, "O", "2"},
      {"HETATM", " O2 ", ' ', "SO4", 'A', 101, "O", "2"}, {"HETATM", " O3 ", ' ', "SO4", 'A', 101, "O", "2"},
      {"HETATM", " O4 ", ' ', "SO4", 'A', 101, "O", "2"}, {"HETATM", " O  ", ' ', "HOH", 'A', 201, "O", "3"},
      {"HETATM", " O  ", ' ', "HOH", 'A', 202, "O", "3"}, {"ATOM", " N  ", ' ', "GLY", 'B', 1, "N", "1"},
      {"ATOM", " CA ", ' ', "GLY", 'B', 1, "C", "1"},     {"ATOM", " C  ", ' ', "GLY", 'B', 1, "C", "1"},
      {"ATOM", " O  ", ' ', "GLY", 'B', 1, "O", "1"},     {"ATOM", " H  ", ' ', "GLY", 'B', 1, "H", "1"},
      {"ATOM", " HA2", ' ', "GLY", 'B', 1, "H", "1"},     {"ATOM", " HA3", ' ', "GLY", 'B', 1, "H", "1"},
  };
  return atoms;
}

// Atom i sits at (2i, i mod 3, −i): no two closer than 2 Å.
glm::dvec3 tinyPosition(std::size_t i) {
  return {2.0 * static_cast<double>(i), static_cast<double>(i % 3), -static_cast<double>(i)};
}

// `models` copies of the tiny structure (model m shifted by 100·m Å in y).
std::string tinyPdb(int models = 1) {
  std::string s = "HEADER    TEST STRUCTURE\nREMARK   1 WRITTEN BY HAND\n";
  for (int m = 0; m < models; ++m) {
    if (models > 1) s += "MODEL     " + std::to_string(m + 1) + "\n";
    int serial = 1;
    for (std::size_t i = 0; i < tinyAtoms().size(); ++i) {
      const TinyAtom& a = tinyAtoms()[i];
      const glm::dvec3 p = tinyPosition(i) + glm::dvec3(0.0, 100.0 * m, 0.0);
      s += atomRecord(a.record, serial++, a.name, a.altloc, a.residue, a.chain, a.seq, p.x, p.y, p.z, a.element);
      if (i == 15 || i + 1 == tinyAtoms().size()) s += "TER\n";  // after the last polymer residue of each chain
    }
    if (models > 1) s += "ENDMDL\n";
  }
  return s + "END\n";
}

// The same structure as mmCIF, with a quoted title, a text field and comments on the way.
std::string tinyCif(const std::string& x0 = "0.000") {
  std::string s =
      "data_TINY\n# a comment\n_entry.id TINY\n_struct.title 'tiny test structure, with \"quotes\"'\n"
      "_struct.pdbx_descriptor\n;A text field\nspanning two lines\n;\n"
      "loop_\n_entity.id\n_entity.type\n1 polymer\n2 non-polymer\n3 water\n#\n"
      "loop_\n_atom_site.group_PDB\n_atom_site.id\n_atom_site.type_symbol\n_atom_site.label_atom_id\n"
      "_atom_site.label_alt_id\n_atom_site.label_comp_id\n_atom_site.label_asym_id\n_atom_site.label_entity_id\n"
      "_atom_site.label_seq_id\n_atom_site.pdbx_PDB_ins_code\n_atom_site.Cartn_x\n_atom_site.Cartn_y\n"
      "_atom_site.Cartn_z\n_atom_site.occupancy\n_atom_site.B_iso_or_equiv\n_atom_site.auth_seq_id\n"
      "_atom_site.auth_asym_id\n_atom_site.pdbx_PDB_model_num\n";
  for (std::size_t i = 0; i < tinyAtoms().size(); ++i) {
    const TinyAtom& a = tinyAtoms()[i];
    std::string name = a.name;
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    const std::string entity = a.entity;
    // label_asym_id: A and B for the chains, C for the sulphate, D for the waters.
    const char* asym = entity == "2" ? "C" : entity == "3" ? "D" : (a.chain == 'A' ? "A" : "B");
    const glm::dvec3 p = tinyPosition(i);
    char row[256];
    std::snprintf(row, sizeof row, "%s %zu %s \"%s\" %c %s %s %s %s ? %s %.3f %.3f 1.00 20.00 %d %c 1\n", a.record,
                  i + 1, a.element, name.c_str(), a.altloc == ' ' ? '.' : a.altloc, a.residue, asym, a.entity,
                  entity == "1" ? std::to_string(a.seq).c_str() : ".",
                  i == 0 ? x0.c_str() : std::to_string(p.x).c_str(), p.y, p.z, a.seq, a.chain);
    s += row;
  }
  return s + "#\n";
}

using mfr::test::expectLoadError;

class MoleculeLoader : public mfr::test::TempDirTest {};

// Per part: name → atoms, from the triangle count at 320 triangles (level 2) per sphere.
std::map<std::string, std::size_t> atomsPerPart(const std::vector<mfr::Object>& objects, std::size_t perSphere = 320) {
  std::map<std::string, std::size_t> out;
  for (const mfr::Object& o : objects) {
    EXPECT_EQ(o.mesh->triangleCount() % perSphere, 0u) << o.name;
    out[o.name] = o.mesh->triangleCount() / perSphere;
  }
  return out;
}

const std::map<std::string, std::size_t> kTinyParts = {{"chain A", 15}, {"chain B", 7}, {"ligands", 5}, {"water", 2}};

// ---- what a structure becomes --------------------------------------------------------------------

TEST_F(MoleculeLoader, PdbPartsAndCounts) {
  const auto objects = mfr::loadModel(write("tiny.pdb", tinyPdb()));
  ASSERT_EQ(objects.size(), 4u);
  EXPECT_EQ(objects[0].name, "chain A");  // chains in file order, then ligands, then water
  EXPECT_EQ(objects[1].name, "chain B");
  EXPECT_EQ(objects[2].name, "ligands");
  EXPECT_EQ(objects[3].name, "water");
  EXPECT_EQ(atomsPerPart(objects), kTinyParts);
  for (const mfr::Object& o : objects) {
    // 162 vertices per level-2 icosphere, coloured per vertex; a white material leaves them as they are.
    EXPECT_EQ(o.mesh->positions.size(), 162 * o.mesh->triangleCount() / 320);
    EXPECT_EQ(o.mesh->colors.size(), o.mesh->positions.size());
    EXPECT_EQ(glm::vec3(o.material.color), glm::vec3(1.0f));
    EXPECT_FLOAT_EQ(o.material.color.a, mfr::Material{}.color.a);
  }
}

// Every sphere: centred on its atom, vertices at the element's van der Waals radius (Bondi 1964:
// C 1.70, N 1.55, O 1.52, S 1.80, H 1.20 Å), unit radial normals, Jmol's element colour.
TEST_F(MoleculeLoader, SpheresSitOnTheAtomsWithRadiusAndColourOfTheElement) {
  const std::map<std::string, std::pair<double, std::uint32_t>> element = {{"C", {1.70, 0x909090}},
                                                                           {"N", {1.55, 0x3050F8}},
                                                                           {"O", {1.52, 0xFF0D0D}},
                                                                           {"S", {1.80, 0xFFFF30}},
                                                                           {"H", {1.20, 0xFFFFFF}}};
  const auto objects = mfr::loadModel(write("tiny.pdb", tinyPdb()));
  ASSERT_EQ(objects.size(), 4u);
  // The atoms of each part in file order (index into tinyAtoms), the second OG left out.
  std::map<std::string, std::vector<std::size_t>> expected;
  for (std::size_t i = 0; i < tinyAtoms().size(); ++i) {
    const TinyAtom& a = tinyAtoms()[i];
    if (a.altloc == 'B') continue;
    const std::string residue = a.residue;
    expected[residue == "HOH" ? "water" : residue == "SO4" ? "ligands" : std::string("chain ") + a.chain].push_back(i);
  }
  for (const mfr::Object& o : objects) {
    const mfr::Mesh& mesh = *o.mesh;
    const std::vector<std::size_t>& atoms = expected[o.name];
    ASSERT_EQ(mesh.positions.size(), atoms.size() * 162) << o.name;
    for (std::size_t s = 0; s < atoms.size(); ++s) {
      const auto [radius, rgb] = element.at(tinyAtoms()[atoms[s]].element);
      const glm::vec4 colour(static_cast<float>(rgb >> 16) / 255.0f, static_cast<float>((rgb >> 8) & 0xFF) / 255.0f,
                             static_cast<float>(rgb & 0xFF) / 255.0f, 1.0f);
      const glm::dvec3 centre = tinyPosition(atoms[s]);
      for (std::size_t k = s * 162; k < (s + 1) * 162; ++k) {
        const glm::dvec3 offset = glm::dvec3(mesh.positions[k]) - centre;
        ASSERT_NEAR(glm::length(offset), radius, 1e-5) << o.name << " sphere " << s;
        ASSERT_NEAR(glm::length(mesh.normals[k]), 1.0f, 1e-6f);
        ASSERT_GT(glm::dot(glm::dvec3(mesh.normals[k]), glm::normalize(offset)), 1.0 - 1e-6) << "normal not radial";
        ASSERT_EQ(mesh.colors[k], colour) << o.name << " sphere " << s << " (" << tinyAtoms()[atoms[s]].element << ")";
      }
    }
    // Every triangle faces outwards (counter-clockwise seen from outside its sphere).
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]), b(mesh.positions[mesh.indices[3 * t + 1]]),
          c(mesh.positions[mesh.indices[3 * t + 2]]);
      const glm::dvec3 centre = tinyPosition(atoms[mesh.indices[3 * t] / 162]);
      ASSERT_GT(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - centre), 0.0) << o.name << " triangle " << t;
    }
    // Bounds: the atoms' centres ± their radii (level 2 has the six axis points as vertices).
    mfr::Bounds b;
    for (const std::size_t i : atoms) {
      const double r = element.at(tinyAtoms()[i].element).first;
      b.extend(tinyPosition(i) - glm::dvec3(r));
      b.extend(tinyPosition(i) + glm::dvec3(r));
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(mesh.bounds().min[k], b.min[k], 1e-5) << o.name;
      EXPECT_NEAR(mesh.bounds().max[k], b.max[k], 1e-5) << o.name;
    }
  }
}

TEST_F(MoleculeLoader, MmcifGivesTheSamePartsAsPdb) {
  const auto pdb = mfr::loadModel(write("tiny.pdb", tinyPdb()));
  const auto cif = mfr::loadModel(write("tiny.cif", tinyCif()));
  EXPECT_EQ(atomsPerPart(cif), kTinyParts);
  ASSERT_EQ(cif.size(), pdb.size());
  for (std::size_t i = 0; i < cif.size(); ++i) {
    EXPECT_EQ(cif[i].name, pdb[i].name);
    // Same spheres in the same order: the PDB's coordinates have 3 decimals, like the mmCIF's.
    ASSERT_EQ(cif[i].mesh->positions.size(), pdb[i].mesh->positions.size());
    for (std::size_t k = 0; k < cif[i].mesh->positions.size(); ++k)
      ASSERT_NEAR(glm::length(cif[i].mesh->positions[k] - pdb[i].mesh->positions[k]), 0.0f, 1e-4f);
    EXPECT_EQ(cif[i].mesh->colors, pdb[i].mesh->colors);
  }
}

TEST_F(MoleculeLoader, GzipAndUpperCaseExtensions) {
  for (const auto& [file, text] : std::vector<std::pair<std::string, std::string>>{{"a.pdb.gz", tinyPdb()},
                                                                                   {"B.PDB", tinyPdb()},
                                                                                   {"c.ent.gz", tinyPdb()},
                                                                                   {"D.CIF.GZ", tinyCif()},
                                                                                   {"e.mmcif", tinyCif()},
                                                                                   {"f.mmCIF.gz", tinyCif()}}) {
    SCOPED_TRACE(file);
    const fs::path p = file.ends_with(".gz") || file.ends_with(".GZ") ? writeGz(file, text) : write(file, text);
    EXPECT_EQ(atomsPerPart(mfr::loadModel(p)), kTinyParts);
  }
  const std::vector<std::string> extensions = mfr::supportedModelExtensions();
  for (const char* ext : {".pdb", ".ent", ".cif", ".mmcif", ".pdb.gz", ".ent.gz", ".cif.gz", ".mmcif.gz"})
    EXPECT_NE(std::find(extensions.begin(), extensions.end(), ext), extensions.end()) << ext;
}

// NMR ensembles: the first model only, and the part names say so.
TEST_F(MoleculeLoader, FirstModelOfAnEnsemble) {
  const auto objects = mfr::loadModel(write("nmr.pdb", tinyPdb(3)));
  std::map<std::string, std::size_t> expected;
  for (const auto& [name, atoms] : kTinyParts) expected[name + " (model 1 of 3)"] = atoms;
  EXPECT_EQ(atomsPerPart(objects), expected);
  for (const mfr::Object& o : objects) EXPECT_LT(o.mesh->bounds().max.y, 50.0) << "an atom of model 2 or 3";
}

// Hydrogens are kept; a blank chain ID is named as such; no TER: gemmi's entity guess (a chain
// whose residues are mostly amino acids is a polymer up to its first other residue; then hetero
// groups and water).
TEST_F(MoleculeLoader, BlankChainHydrogensAndNoTer) {
  std::string s;
  int serial = 1;
  for (const char* name : {" N  ", " CA ", " C  ", " O  ", " H  ", " HA2", " HA3"})
    s += atomRecord("ATOM", serial, name, ' ', "GLY", ' ', 1, serial * 2.0, 0, 0,
                    name[1] == 'H'   ? "H"
                    : name[1] == 'C' ? "C"
                    : name[1] == 'N' ? "N"
                                     : "O"),
        ++serial;
  for (int residue = 2; residue <= 4; ++residue)
    for (const char* name : {" N  ", " CA ", " C  ", " O  "})
      s += atomRecord("ATOM", serial, name, ' ', "GLY", ' ', residue, serial * 2.0, 0, 0,
                      name[1] == 'C'   ? "C"
                      : name[1] == 'N' ? "N"
                                       : "O"),
          ++serial;
  s += atomRecord("HETATM", serial, "ZN  ", ' ', " ZN", ' ', 5, serial * 2.0, 0, 0, "ZN"), ++serial;
  s += atomRecord("HETATM", serial, " O  ", ' ', "HOH", ' ', 6, serial * 2.0, 0, 0, "O");
  const auto objects = mfr::loadModel(write("blank.pdb", s));
  EXPECT_EQ(atomsPerPart(objects),
            (std::map<std::string, std::size_t>{{"chain (blank)", 19}, {"ligands", 1}, {"water", 1}}));
}

// Residues sorted into parts by their kind and bonds, whatever the TER records and residue order
// (as MD programs write files: no TER, no element columns, atom names from column 13, where gemmi
// reads Cα "CA  " as calcium). gemmi's guess took a chain's polymer to end at its first residue
// not of the chain's type: a chain starting with an acetyl cap was all ligands, and a chain of
// protein then DNA lost its DNA.
TEST_F(MoleculeLoader, ResiduesSortedByKindAndBonds) {
  std::string s;
  int serial = 1;
  const auto atom = [&](const char* record, const char* name, const char* residue, char chain, int seq,
                        const glm::dvec3& p) {
    s += atomRecord(record, serial++, name, ' ', residue, chain, seq, p.x, p.y, p.z, "");
  };
  // A peptide along x, 3.8 Å per residue, each C bonded to the next N (1.33 Å).
  const auto peptide = [&](const char* record, const char* residue, char chain, int seq, double x, bool selenium) {
    atom(record, "N   ", residue, chain, seq, {x, 0.0, 0.0});
    atom(record, "CA  ", residue, chain, seq, {x + 1.45, 0.3, 0.0});
    atom(record, "C   ", residue, chain, seq, {x + 2.47, 0.0, 0.0});
    atom(record, "O   ", residue, chain, seq, {x + 2.47, 1.23, 0.0});
    atom(record, "CB  ", residue, chain, seq, {x + 1.45, -0.5, 1.3});
    if (selenium) {
      atom(record, "CG  ", residue, chain, seq, {x + 1.45, -0.5, 2.8});
      atom(record, "SE  ", residue, chain, seq, {x + 1.45, -0.5, 4.7});
      atom(record, "CE  ", residue, chain, seq, {x + 1.45, -0.5, 6.6});
    }
  };
  // Chain A: ACE, ALA, ALA, MSE (HETATM, bonded into the chain), ALA, NME; then a free glutamate
  // (HETATM, bonded to nothing), a ligand whose names read as chlorine, and GROMACS water (SOL).
  atom("ATOM", "CH3 ", "ACE", 'A', 0, {-2.8, 0.0, 0.0});
  atom("ATOM", "C   ", "ACE", 'A', 0, {-1.33, 0.0, 0.0});
  atom("ATOM", "O   ", "ACE", 'A', 0, {-1.33, 1.23, 0.0});
  peptide("ATOM", "ALA", 'A', 1, 0.0, false);
  peptide("ATOM", "ALA", 'A', 2, 3.8, false);
  peptide("HETATM", "MSE", 'A', 3, 7.6, true);
  peptide("ATOM", "ALA", 'A', 4, 11.4, false);
  atom("ATOM", "N   ", "NME", 'A', 5, {15.2, 0.0, 0.0});
  atom("ATOM", "CH3 ", "NME", 'A', 5, {16.65, 0.3, 0.0});
  peptide("HETATM", "GLU", 'A', 6, 30.0, false);
  atom("HETATM", "CL1 ", "LIG", 'A', 7, {40.0, 0.0, 0.0});
  atom("HETATM", "CL2 ", "LIG", 'A', 7, {41.8, 0.0, 0.0});
  // MD programs write ligands as ATOM records: an untabulated cofactor with N, CA and C atoms bonded
  // to nothing, and an iodide (gemmi's table reads "I" as inosine), are ligands.
  atom("ATOM", "N   ", "SAM", 'A', 9, {60.0, 0.0, 0.0});
  atom("ATOM", "CA  ", "SAM", 'A', 9, {61.45, 0.3, 0.0});
  atom("ATOM", "C   ", "SAM", 'A', 9, {62.47, 0.0, 0.0});
  atom("ATOM", "I   ", "  I", 'A', 10, {70.0, 0.0, 0.0});
  atom("ATOM", "OW  ", "SOL", 'A', 8, {50.0, 0.0, 0.0});
  atom("ATOM", "HW1 ", "SOL", 'A', 8, {50.96, 0.0, 0.0});
  atom("ATOM", "HW2 ", "SOL", 'A', 8, {49.76, 0.93, 0.0});
  // Chain B: two alanines, then two DNA nucleotides, each O3' bonded to the next P (1.6 Å).
  peptide("ATOM", "ALA", 'B', 1, 0.0, false);
  peptide("ATOM", "ALA", 'B', 2, 3.8, false);
  // An element the record states is kept, though other records leave theirs blank.
  s += atomRecord("ATOM", serial++, "HG  ", ' ', "ALA", 'B', 2, 5.0, -1.5, 2.0, "HG");
  for (int k = 0; k < 2; ++k) {
    const double x = 10.0 + 5.0 * k;
    atom("ATOM", "P   ", " DA", 'B', 3 + k, {x, 5.0, 0.0});
    atom("ATOM", "O5' ", " DA", 'B', 3 + k, {x + 1.0, 6.2, 0.0});
    atom("ATOM", "C5' ", " DA", 'B', 3 + k, {x + 2.0, 7.3, 0.0});
    atom("ATOM", "C4' ", " DA", 'B', 3 + k, {x + 3.0, 6.2, 0.0});
    atom("ATOM", "C3' ", " DA", 'B', 3 + k, {x + 2.9, 4.8, 0.0});
    atom("ATOM", "O3' ", " DA", 'B', 3 + k, {x + 3.4, 5.0, 0.0});  // 1.6 Å from the next P
  }
  const fs::path file = write("md.pdb", s + "END\n");
  // 3 + 5 + 5 + 8 + 5 + 2 in chain A, 5 + 6 + 6 + 6 in chain B, 5 + 2 + 3 + 1 ligand atoms, 3 water.
  EXPECT_EQ(atomsPerPart(mfr::loadModel(file)),
            (std::map<std::string, std::size_t>{{"chain A", 28}, {"chain B", 23}, {"ligands", 11}, {"water", 3}}));
  const mfr::MoleculeStructure m = mfr::readMoleculeStructure(file);
  std::map<int, std::size_t> elements;
  for (const mfr::MoleculeAtom& a : m.atoms) ++elements[a.atomicNumber];
  // Cα carbon, not calcium (also the free glutamate's); water's OW and HW1 oxygen and hydrogen; the
  // selenium stays; the ligand's chlorines are left as gemmi reads them.
  EXPECT_EQ(elements, (std::map<int, std::size_t>{
                          {1, 2}, {6, 34}, {7, 9}, {8, 13}, {15, 2}, {17, 2}, {34, 1}, {53, 1}, {80, 1}}));
  std::string residues;
  for (const mfr::BackboneResidue& r : m.residues) residues += r.chain + r.name + " ";
  EXPECT_EQ(residues, "AACE AALA AALA AMSE AALA ANME BALA BALA BDA BDA ");
}

// Elements where an MD or old file gives none and the atom name alone is ambiguous: CHARMM's ions
// are named after their residue (gemmi read SOD as no element and POT as polonium), and "HG" from
// column 13 is a serine's γ-hydrogen in an AMBER file but the mercury of S-(methylmercury)cysteine
// (CMH) in an old PDB file — told apart by the distance to the nearest atom of the residue.
TEST_F(MoleculeLoader, IonsAndMercuryWithoutElementColumns) {
  std::string s;
  int serial = 1;
  const auto atom = [&](const char* name, const char* residue, int seq, const glm::dvec3& p) {
    s += atomRecord("ATOM", serial++, name, ' ', residue, 'A', seq, p.x, p.y, p.z, "");
  };
  const auto backbone = [&](const char* residue, int seq, double x) {
    atom("N   ", residue, seq, {x, 0.0, 0.0});
    atom("CA  ", residue, seq, {x + 1.45, 0.3, 0.0});
    atom("C   ", residue, seq, {x + 2.47, 0.0, 0.0});
    atom("O   ", residue, seq, {x + 2.47, 1.23, 0.0});
    atom("CB  ", residue, seq, {x + 1.45, -0.5, 1.45});
  };
  backbone("SER", 1, 0.0);
  atom("OG  ", "SER", 1, {1.45, -0.5, 2.88});
  atom("HG  ", "SER", 1, {1.45, 0.46, 2.88});  // 0.96 Å from OG
  backbone("CMH", 2, 3.8);
  atom("SG  ", "CMH", 2, {5.25, -0.5, 3.27});  // 1.82 Å from CB
  atom("HG  ", "CMH", 2, {5.25, -0.5, 5.67});  // 2.40 Å from SG
  atom("CM  ", "CMH", 2, {5.25, -0.5, 7.77});  // 2.10 Å from HG
  const std::array<const char*, 6> ions = {"SOD", "POT", "CLA", "CAL", "CES", "ZN2"};
  for (std::size_t i = 0; i < ions.size(); ++i)
    atom(i == 5 ? "ZN  " : (std::string(ions[i]) + " ").c_str(), ions[i], 10 + static_cast<int>(i),
         {20.0 + 5.0 * static_cast<double>(i), 0.0, 0.0});
  // Review cases: the mercury in two alternative locations 0.8 Å apart (each other's no bonding
  // partner); two SOD ions numbered as one residue; ions named from column 14 (" SOD", as MDTraj
  // and OpenMM write them; gemmi read S and P); a leucine's HG moved 30 Å away (a periodic box):
  // in a residue of gemmi's table, still a hydrogen.
  s += atomRecord("ATOM", serial++, "HG  ", 'B', "CMH", 'A', 2, 5.25, 0.3, 5.67, "");  // 22
  atom("SOD ", "SOD", 20, {60.0, 0.0, 0.0});                                           // 23
  atom("SOD ", "SOD", 20, {65.0, 0.0, 0.0});                                           // 24
  atom(" SOD", "SOD", 21, {70.0, 0.0, 0.0});                                           // 25
  atom(" POT", "POT", 22, {75.0, 0.0, 0.0});                                           // 26
  atom("N   ", "LEU", 30, {100.0, 0.0, 0.0});                                          // 27
  atom("CA  ", "LEU", 30, {101.45, 0.3, 0.0});                                         // 28
  atom("C   ", "LEU", 30, {102.47, 0.0, 0.0});                                         // 29
  atom("HG  ", "LEU", 30, {130.0, 0.0, 0.0});                                          // 30
  // Serials past 99,999 (where MD files put their ions): hybrid-36, and VMD's "*****".
  for (const auto& [text, residue] : {std::pair{"A0000", "SOD"}, std::pair{"*****", "POT"}}) {
    std::string line = atomRecord("HETATM", 0, (std::string(residue) + " ").c_str(), ' ', residue, 'A', 40, 90.0,
                                  residue[0] == 'S' ? 0.0 : 5.0, 0.0, "");
    line.replace(6, 5, text);
    s += line;
  }
  const mfr::MoleculeStructure m = mfr::readMoleculeStructure(write("md-ions.pdb", s + "END\n"));
  std::map<int, int> elementOf;  // serial → atomic number
  for (const mfr::MoleculeAtom& a : m.atoms) elementOf[a.serial] = a.atomicNumber;
  EXPECT_EQ(elementOf[7], 1) << "serine's HG";
  EXPECT_EQ(elementOf[13], 16) << "CMH's SG";
  EXPECT_EQ(elementOf[14], 80) << "CMH's HG";
  EXPECT_EQ(elementOf[15], 6) << "CMH's CM";
  EXPECT_EQ(
      (std::vector<int>{elementOf[16], elementOf[17], elementOf[18], elementOf[19], elementOf[20], elementOf[21]}),
      (std::vector<int>{11, 19, 17, 20, 55, 30}))
      << "SOD POT CLA CAL CES ZN2";
  EXPECT_EQ(elementOf[14], 80) << "CMH's HG beside its other location";
  EXPECT_EQ((std::vector<int>{elementOf[23], elementOf[24], elementOf[25], elementOf[26], elementOf[30]}),
            (std::vector<int>{11, 11, 11, 19, 1}))
      << "SOD SOD (one residue), SOD POT (from column 14), LEU's far HG";
  EXPECT_EQ(elementOf[100000], 11) << "SOD with a hybrid-36 serial";
  EXPECT_EQ(elementOf[0], 19) << "POT with the serial *****";
}

// AMBER's ions, from LEaP's older libraries (IP = Na⁺, IM = Cl⁻) and its "Na+"-style names, where
// the file gives no element: read as unknown (X) or as a wrong element from the name's first letters.
TEST_F(MoleculeLoader, AmberIonsWithoutElementColumns) {
  std::string s;
  int serial = 1;
  const std::array<std::pair<const char*, int>, 7> ions = {
      {{"IP", 11}, {"IM", 17}, {"Na+", 11}, {"Cl-", 17}, {"K+", 19}, {"Li+", 3}, {"Cs+", 55}}};
  for (std::size_t i = 0; i < ions.size(); ++i) {
    const std::string name = ions[i].first;
    s += atomRecord("ATOM", serial++, (name + std::string(4 - name.size(), ' ')).c_str(), ' ', ions[i].first, 'A',
                    static_cast<int>(i) + 1, 5.0 * static_cast<double>(i), 0.0, 0.0, "");
  }
  const mfr::MoleculeStructure m = mfr::readMoleculeStructure(write("amber-ions.pdb", s + "END\n"));
  ASSERT_EQ(m.atoms.size(), ions.size());
  for (std::size_t i = 0; i < ions.size(); ++i) EXPECT_EQ(m.atoms[i].atomicNumber, ions[i].second) << ions[i].first;
}

// An mmCIF file without _entity: gemmi guesses from the subchains (a one-residue ALA subchain a
// ligand, two SOL residues a polymer); the residues are sorted by kind and bonds instead.
TEST_F(MoleculeLoader, MmcifWithoutEntitiesIsSortedByKind) {
  std::string cif =
      "data_X\nloop_\n_atom_site.group_PDB\n_atom_site.id\n_atom_site.type_symbol\n_atom_site.label_atom_id\n"
      "_atom_site.label_alt_id\n_atom_site.label_comp_id\n_atom_site.label_asym_id\n_atom_site.label_entity_id\n"
      "_atom_site.label_seq_id\n_atom_site.Cartn_x\n_atom_site.Cartn_y\n_atom_site.Cartn_z\n_atom_site.occupancy\n"
      "_atom_site.B_iso_or_equiv\n_atom_site.auth_seq_id\n_atom_site.auth_asym_id\n_atom_site.pdbx_PDB_model_num\n"
      "ATOM 1 N N . ALA A 1 1 -1.649 0.885 0.183 1 0 1 A 1\nATOM 2 C CA . ALA A 1 1 -0.244 1.035 -0.187 1 0 1 A 1\n"
      "ATOM 3 C C . ALA A 1 1 0.221 2.456 0.023 1 0 1 A 1\nATOM 4 O O . ALA A 1 1 -0.530 3.334 0.466 1 0 1 A 1\n";
  for (int w = 0; w < 2; ++w) {
    const double x = 40.0 + 3.0 * w;
    char rows[400];
    std::snprintf(
        rows, sizeof rows,
        "HETATM %d O OW . SOL B 2 . %.2f 60 60 1 0 %d A 1\nHETATM %d H HW1 . SOL B 2 . %.2f 60 60 1 0 %d A 1\n"
        "HETATM %d H HW2 . SOL B 2 . %.2f 60.93 60 1 0 %d A 1\n",
        5 + 3 * w, x, 2 + w, 6 + 3 * w, x + 0.96, 2 + w, 7 + 3 * w, x - 0.24, 2 + w);
    cif += rows;
  }
  EXPECT_EQ(atomsPerPart(mfr::loadModel(write("noentity.cif", cif))),
            (std::map<std::string, std::size_t>{{"chain A", 4}, {"water", 6}}));
}

// The tessellation rule: 320 triangles per sphere while the structure stays within 2,000,000
// triangles (6,250 atoms), then 80 (up to 25,000 atoms), then 20.
TEST_F(MoleculeLoader, TrianglesPerSphereKeepTheStructureUnderTheCap) {
  for (const auto& [atoms, perSphere] :
       std::vector<std::pair<int, std::size_t>>{{6250, 320}, {6251, 80}, {25000, 80}, {25001, 20}}) {
    std::string s;
    for (int i = 0; i < atoms; ++i)  // water on a 3 Å grid, 50 × 50 per layer
      s += atomRecord("HETATM", i % 99999 + 1, " O  ", ' ', "HOH", 'W', i % 9999 + 1, 3.0 * (i % 50),
                      3.0 * ((i / 50) % 50), 3.0 * (i / 2500), "O");
    const auto objects = mfr::loadModel(write("grid" + std::to_string(atoms) + ".pdb", s));
    ASSERT_EQ(objects.size(), 1u);
    EXPECT_EQ(objects[0].name, "water");
    EXPECT_EQ(objects[0].mesh->triangleCount(), static_cast<std::size_t>(atoms) * perSphere) << atoms << " atoms";
    // 10·4^L + 2 vertices per sphere.
    EXPECT_EQ(objects[0].mesh->positions.size(), static_cast<std::size_t>(atoms) * (perSphere / 2 + 2));
  }
}

TEST_F(MoleculeLoader, ProgressAndCancel) {
  const fs::path p = write("tiny.pdb", tinyPdb());
  std::vector<double> reports;
  mfr::LoadProgress progress;
  progress.report = [&](double f) {
    reports.push_back(f);
    return true;
  };
  ASSERT_EQ(mfr::loadModel(p, progress).size(), 4u);
  ASSERT_GE(reports.size(), 2u + 4u);  // start, after parsing, one per part, the end
  EXPECT_EQ(reports.front(), 0.0);
  EXPECT_EQ(reports.back(), 1.0);
  for (std::size_t i = 1; i < reports.size(); ++i) EXPECT_GE(reports[i], reports[i - 1]);
  // Cancelling at each report in turn stops the load there.
  for (std::size_t stopAt = 0; stopAt + 1 < reports.size(); ++stopAt) {
    std::size_t calls = 0;
    mfr::LoadProgress cancel;
    cancel.report = [&](double) { return calls++ < stopAt; };
    EXPECT_THROW(mfr::loadModel(p, cancel), mfr::LoadCancelled) << "stop at report " << stopAt;
    EXPECT_EQ(calls, stopAt + 1) << "reports after the cancel";
  }
}

// A scene file's "color" replaces the element colours (Material::vertexColors false) — its
// documented meaning, "overrides the file's colours" — while "opacity" alone keeps them; the
// oracle then shades every fragment of such a part in that colour.
TEST_F(MoleculeLoader, SceneFileColourReplacesElementColours) {
  write("tiny.pdb", tinyPdb());
  const fs::path own =
      write("own.mfrscene", R"({"objects": [{"file": "tiny.pdb", "color": [0.2, 0.4, 0.9], "opacity": 1}]})");
  const fs::path see = write("see.mfrscene", R"({"objects": [{"file": "tiny.pdb", "opacity": 1}]})");
  const mfr::Scene coloured = mfr::loadScene(own), elements = mfr::loadScene(see);
  ASSERT_EQ(coloured.objects.size(), 4u);
  ASSERT_EQ(elements.objects.size(), 4u);
  for (const mfr::Object& o : coloured.objects) {
    EXPECT_FALSE(o.material.vertexColors) << o.name;
    EXPECT_EQ(o.material.color, glm::vec4(0.2f, 0.4f, 0.9f, 1.0f));
  }
  for (const mfr::Object& o : elements.objects) {
    EXPECT_TRUE(o.material.vertexColors) << o.name;
    EXPECT_EQ(o.material.color, glm::vec4(1.0f));
  }
  // Looking down −z at the row of atoms: the first layer of every pixel.
  const auto firstFragments = [](const mfr::Scene& scene) {
    const mfr::FragmentLists lists = mfr::castFragments(scene, scene.view("fit"), 96, 24);
    std::vector<std::uint32_t> colours;
    for (std::size_t i = 0; i + 1 < lists.offsets.size(); ++i)
      if (lists.offsets[i + 1] > lists.offsets[i]) colours.push_back(lists.fragments[lists.offsets[i]].color);
    return colours;
  };
  std::size_t red = 0;
  for (const std::uint32_t c : firstFragments(elements)) red += (c & 0xFF) > 3 * ((c >> 16) & 0xFF) + 20;
  EXPECT_GT(red, 0u) << "oxygens are red";
  const std::vector<std::uint32_t> own_ = firstFragments(coloured);
  ASSERT_FALSE(own_.empty());
  for (const std::uint32_t c : own_) {
    const double r = c & 0xFF, g = (c >> 8) & 0xFF, b = (c >> 16) & 0xFF;  // (0.2, 0.4, 0.9) × light
    ASSERT_NEAR(g / r, 2.0, 4.0 / r + 0.02) << std::hex << c;
    ASSERT_NEAR(b / r, 4.5, 9.0 / r + 0.05) << std::hex << c;
  }
}

// ---- bad input ----------------------------------------------------------------------------------

TEST_F(MoleculeLoader, MissingAndEmpty) {
  expectLoadError(dir() / "nothing.pdb", "no such file");
  expectLoadError(write("empty.pdb", ""), "empty file");
  expectLoadError(write("empty.cif", ""), "empty file");
  expectLoadError(writeGz("empty.cif.gz", ""), "empty file");
  expectLoadError(write("blank.cif", "  \n# only a comment\n"), "no CIF data block");
}

TEST_F(MoleculeLoader, GarbageAndNoAtoms) {
  std::string binary;
  for (int i = 0; i < 4096; ++i) binary += static_cast<char>((i * 7919) % 251);
  expectLoadError(write("binary.pdb", binary), "no atoms");
  expectLoadError(write("binary.cif", binary), "binary.cif: line 1, column 1: expected block header (data_)");
  expectLoadError(write("header.pdb", "HEADER    NOTHING HERE\nREMARK   2 RESOLUTION. 2.0 ANGSTROMS.\nEND\n"),
                  "no atoms (no ATOM or HETATM records");
  expectLoadError(write("text.cif", "this is not a CIF file\n"), "expected block header (data_)");
  expectLoadError(write("noatoms.cif", "data_X\n_entry.id X\nloop_\n_entity.id\n_entity.type\n1 polymer\n"),
                  "no atoms: not a macromolecular mmCIF file");
  expectLoadError(write("nacl.cif",
                        "data_nacl\n_cell_length_a 5.64\n_symmetry_space_group_name_H-M 'F m -3 m'\nloop_\n"
                        "_atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n_atom_site_fract_z\n"
                        "Na1 0 0 0\nCl1 0.5 0.5 0.5\n"),
                  "a small-molecule CIF");
  // An mmCIF file named .pdb, and a PDB file named .cif.
  expectLoadError(write("cif.pdb", tinyCif()), "perhaps it is cif not pdb");
  expectLoadError(write("pdb.cif", tinyPdb()), "expected block header (data_)");
}

TEST_F(MoleculeLoader, Truncated) {
  const std::string pdb = tinyPdb();
  // Cut inside the coordinates of the 10th atom, and after them (gemmi would take that record as
  // complete): the last record is shorter than the one before.
  const std::size_t tenth = pdb.find("ATOM     10");
  ASSERT_NE(tenth, std::string::npos);
  expectLoadError(write("cut40.pdb", pdb.substr(0, tenth + 40)),
                  "truncated file: the last ATOM/HETATM record ends at column 40 (the one before has 80)");
  expectLoadError(write("cut60.pdb", pdb.substr(0, tenth + 60)),
                  "truncated file: the last ATOM/HETATM record ends at column 60");
  // A short record inside the file: gemmi's own check.
  std::string shortLine = pdb;
  shortLine.erase(tenth + 40, 40);
  expectLoadError(write("short.pdb", shortLine), "The line is too short to be correct");
  const std::string cif = tinyCif();
  const std::size_t row = cif.find("\nATOM 12 ");
  ASSERT_NE(row, std::string::npos);
  expectLoadError(write("cut.cif", cif.substr(0, row + 20)),
                  "Wrong number of values in the loop (truncated or corrupt?)");
  expectLoadError(write("quote.cif", cif.substr(0, cif.find("quotes") + 3)),
                  "line 4, column 46: unterminated 'string'");
  expectLoadError(write("field.cif", cif.substr(0, cif.find("two lines") + 4)), "unterminated text field");
  // A cut gzip stream.
  const fs::path whole = writeGz("whole.pdb.gz", pdb);
  std::ifstream in(whole, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  expectLoadError(write("cut.pdb.gz", bytes.substr(0, bytes.size() / 2)), "gzip");
}

TEST_F(MoleculeLoader, AbsurdCoordinates) {
  expectLoadError(write("nan.cif", tinyCif("nan")), "), not finite or beyond ±100000 Å");
  expectLoadError(write("unknown.cif", tinyCif("?")), "not finite or beyond");
  expectLoadError(write("huge.cif", tinyCif("1e30")), "has coordinates (1e+30, 0, ");
  std::string pdb = tinyPdb();
  pdb.replace(pdb.find("ATOM      1") + 30, 8, "99999999");  // x of the first atom
  expectLoadError(write("huge.pdb", pdb), "atom 1 (N of ALA 1, chain 'A') has coordinates (1e+08, 0, ");
  // Not numbers (gemmi read "1.0x0" as 1 and a blank as 0): refused, naming the line and columns.
  for (const auto& [text, reason] :
       {std::pair{"   1.0x0", "line 4: the y coordinate (columns 39–46) is not a number: '1.0x0'"},
        std::pair{"        ", "line 4: the y coordinate (columns 39–46) is blank"},
        std::pair{"   -.   ", "line 4: the y coordinate (columns 39–46) is not a number: '-.'"},
        std::pair{"  1.2.3 ", "line 4: the y coordinate (columns 39–46) is not a number: '1.2.3'"}}) {
    std::string bad = tinyPdb();
    bad.replace(bad.find("ATOM      2") + 38, 8, text);  // y of the second atom, on line 4
    expectLoadError(write("nan.pdb", bad), reason);
  }
}

TEST_F(MoleculeLoader, BrokenMmcifSyntax) {
  const std::string head = "data_X\nloop_\n_atom_site.id\n_atom_site.Cartn_x\n";
  // gemmi's CIF parser (PEGTL) and its checks, positions spelled out.
  expectLoadError(write("tag.cif", "data_X\n_entry.id\n_entry.title x\n"), "line 2 in data_X: _entry.id has no value");
  expectLoadError(write("loop.cif", "data_X\nloop_\n1 2 3\n"), "line 3, column 1: parse error");
  expectLoadError(write("stop.cif", "data_X\nstop_\n"), "line 2, column 1: parse error");
  expectLoadError(write("value.cif", "data_X\n_a 1 2\n"), "line 2, column 6: parse error");
  expectLoadError(write("dup.cif", "data_X\n_a 1\n_A 2\n"), "line 3 in data_X: duplicate tag _A");
  expectLoadError(write("frame.cif", "data_X\nsave_f\n_a 1\n"), "line 4, column 1: parse error");
  expectLoadError(write("columns.cif", head + "1 0.0\n"), "mmCIF _atom_site has no _atom_site.type_symbol column");
}

}  // namespace
