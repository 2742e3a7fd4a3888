// Real molecular structures from Debian packages (pymol-data, python-biopython-doc; shared/DATA.md)
// load as the files themselves say. The expected atoms come from the test's own reading of each
// file, not from gemmi: for PDB the ATOM/HETATM records of the first model split by chain ID, with
// HOH as water and HETATM residues that the chain's SEQRES does not list as ligands; for mmCIF the
// _atom_site rows of the first model split by the _entity table's types. Both keep the first
// alternative location at each residue position. A missing file is a failure, not a skip.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/color_map.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::expectLoadError;
using mfr::test::readTestFile;

const fs::path kPymolDemo = "/usr/share/pymol/data/demo";
const fs::path kBiopython = "/usr/share/doc/python-biopython-doc/Tests/PDB";

fs::path requireFile(const fs::path& path, const std::string& package) {
  if (!fs::exists(path)) ADD_FAILURE() << "missing " << path << " (from " << package << "; scripts/setup installs it)";
  return path;
}

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// An atom as the test reads it from the file.
struct RefAtom {
  std::string part;
  glm::dvec3 position;
  std::string element;  // upper case
  // PDB only (columns 61–66, 55–60, 23–26): the fields a sphere is coloured by.
  bool hasFields = false;
  float bFactor = 0.0f, occupancy = 0.0f, residue = 0.0f;
};

// A part: name and atoms in file order. Parts in the loader's order: chains as they first
// appear, then ligands, then water.
using RefParts = std::vector<std::pair<std::string, std::vector<RefAtom>>>;

RefParts group(const std::vector<RefAtom>& atoms) {
  RefParts chains;
  std::vector<RefAtom> ligands, water;
  for (const RefAtom& a : atoms) {
    if (a.part == "ligands")
      ligands.push_back(a);
    else if (a.part == "water")
      water.push_back(a);
    else {
      auto it = std::find_if(chains.begin(), chains.end(), [&](const auto& p) { return p.first == a.part; });
      if (it == chains.end()) it = chains.insert(chains.end(), {a.part, {}});
      it->second.push_back(a);
    }
  }
  if (!ligands.empty()) chains.push_back({"ligands", ligands});
  if (!water.empty()) chains.push_back({"water", water});
  return chains;
}

// PDB: fixed columns (chain 22, residue 18–20, altloc 17, residue number and insertion code
// 23–27, x y z 31–54, element 77–78).
RefParts readPdb(const std::string& text) {
  std::map<char, std::set<std::string>> seqres;
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
    if (line.rfind("SEQRES", 0) == 0 && line.size() > 19) {
      std::istringstream names(line.substr(19));
      for (std::string n; names >> n;) seqres[line[11]].insert(n);
    }
  }
  std::vector<RefAtom> atoms;
  std::map<std::string, char> firstAltloc;
  for (const std::string& line : lines) {
    if (line.rfind("ENDMDL", 0) == 0) break;
    const bool atom = line.rfind("ATOM  ", 0) == 0, het = line.rfind("HETATM", 0) == 0;
    if (!atom && !het) continue;
    const char chain = line[21], altloc = line[16];
    const std::string residue = trim(line.substr(17, 3));
    if (altloc != ' ') {
      const char first = firstAltloc.try_emplace(std::string(1, chain) + line.substr(22, 5), altloc).first->second;
      if (altloc != first) continue;
    }
    RefAtom a;
    if (residue == "HOH")
      a.part = "water";
    else if (atom || seqres[chain].count(residue) != 0)
      a.part = chain == ' ' ? "chain (blank)" : std::string("chain ") + chain;
    else
      a.part = "ligands";
    a.position = {std::stod(line.substr(30, 8)), std::stod(line.substr(38, 8)), std::stod(line.substr(46, 8))};
    a.hasFields = true;
    a.occupancy = std::stof(line.substr(54, 6));
    a.bFactor = std::stof(line.substr(60, 6));
    a.residue = std::stof(line.substr(22, 4));
    if (line.size() >= 78 && (std::isalpha(static_cast<unsigned char>(line[76])) != 0 ||
                              std::isalpha(static_cast<unsigned char>(line[77])) != 0)) {
      a.element = trim(line.substr(76, 2));
    } else {
      // Older files: the element symbol right-justified in columns 13–14 of the atom name (a digit
      // in column 13 numbers hydrogens, as in "1HB ").
      const std::string name = line.substr(12, 2);
      a.element = name[0] == ' ' || std::isdigit(static_cast<unsigned char>(name[0])) != 0 ? name.substr(1) : name;
    }
    atoms.push_back(a);
  }
  return group(atoms);
}

// CIF tokens: white-space separated, '…' and "…" quoted (the quote ends before white space), text
// fields between lines starting with ';', comments from '#'.
std::vector<std::string> cifTokens(const std::string& text) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
      ++i;
    } else if (c == '#') {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (c == ';' && (i == 0 || text[i - 1] == '\n')) {
      const std::size_t end = text.find("\n;", i);
      out.push_back(text.substr(i + 1, end - i - 1));
      i = end + 2;
    } else if (c == '\'' || c == '"') {
      std::size_t end = i + 1;
      while (!(text[end] == c && (end + 1 == text.size() || std::isspace(static_cast<unsigned char>(text[end + 1])))))
        ++end;
      out.push_back(text.substr(i + 1, end - i - 1));
      i = end + 1;
    } else {
      std::size_t end = i;
      while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
      out.push_back(text.substr(i, end - i));
      i = end;
    }
  }
  return out;
}

// The category `prefix` ("_atom_site.") as rows of tag → value, from a loop or from tag-value pairs.
std::vector<std::map<std::string, std::string>> cifCategory(const std::vector<std::string>& tokens,
                                                            const std::string& prefix) {
  std::vector<std::map<std::string, std::string>> rows;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    if (tokens[i] == "loop_" && i + 1 < tokens.size() && tokens[i + 1].rfind(prefix, 0) == 0) {
      std::vector<std::string> tags;
      std::size_t k = i + 1;
      for (; k < tokens.size() && tokens[k].rfind(prefix, 0) == 0; ++k) tags.push_back(tokens[k].substr(prefix.size()));
      for (; k + tags.size() <= tokens.size() && tokens[k] != "loop_" && tokens[k][0] != '_' &&
             tokens[k].rfind("data_", 0) != 0;
           k += tags.size()) {
        std::map<std::string, std::string> row;
        for (std::size_t t = 0; t < tags.size(); ++t) row[tags[t]] = tokens[k + t];
        rows.push_back(std::move(row));
      }
      return rows;
    }
    if (tokens[i].rfind(prefix, 0) == 0 && i + 1 < tokens.size()) {
      if (rows.empty()) rows.emplace_back();
      rows[0][tokens[i].substr(prefix.size())] = tokens[i + 1];
      ++i;
    }
  }
  return rows;
}

RefParts readMmcif(const std::string& text) {
  const std::vector<std::string> tokens = cifTokens(text);
  std::map<std::string, std::string> entityType;
  for (const auto& row : cifCategory(tokens, "_entity.")) entityType[row.at("id")] = row.at("type");
  std::vector<RefAtom> atoms;
  std::map<std::string, std::string> firstAltloc;
  std::string model;
  for (const auto& row : cifCategory(tokens, "_atom_site.")) {
    if (model.empty()) model = row.at("pdbx_PDB_model_num");
    if (row.at("pdbx_PDB_model_num") != model) continue;
    const std::string altloc = row.at("label_alt_id");
    if (altloc != "." && altloc != "?") {
      const std::string key = row.at("auth_asym_id") + "/" + row.at("auth_seq_id") + "/" + row.at("pdbx_PDB_ins_code");
      if (firstAltloc.try_emplace(key, altloc).first->second != altloc) continue;
    }
    RefAtom a;
    const std::string type = entityType.at(row.at("label_entity_id"));
    a.part = type == "polymer" ? "chain " + row.at("auth_asym_id") : type == "water" ? "water" : "ligands";
    a.position = {std::stod(row.at("Cartn_x")), std::stod(row.at("Cartn_y")), std::stod(row.at("Cartn_z"))};
    a.element = row.at("type_symbol");
    std::transform(a.element.begin(), a.element.end(), a.element.begin(), ::toupper);
    atoms.push_back(a);
  }
  return group(atoms);
}

// Van der Waals radii (Bondi 1964, J. Phys. Chem. 68, 441; Na from Bondi too) and Jmol colours
// (jmol.sourceforge.net/jscolors) of the elements in these files.
struct ElementLook {
  double radius;
  std::uint32_t rgb;
};
const std::map<std::string, ElementLook>& elements() {
  static const std::map<std::string, ElementLook> table = {
      {"H", {1.20, 0xFFFFFF}}, {"C", {1.70, 0x909090}},  {"N", {1.55, 0x3050F8}},
      {"O", {1.52, 0xFF0D0D}}, {"F", {1.47, 0x90E050}},  {"P", {1.80, 0xFF8000}},
      {"S", {1.80, 0xFFFF30}}, {"SE", {1.90, 0xFFA100}}, {"NA", {2.27, 0xAB5CF2}}};
  return table;
}

glm::vec4 rgba(std::uint32_t rgb) {
  return {static_cast<float>(rgb >> 16) / 255.0f, static_cast<float>((rgb >> 8) & 0xFF) / 255.0f,
          static_cast<float>(rgb & 0xFF) / 255.0f, 1.0f};
}

// The loaded parts match the reference atom for atom: names in order, sphere i of a part on atom i
// of that part, at its element's radius and in its colour, unit radial normals, bounds = centres ±
// radii. `perSphere`: triangles per sphere by the documented rule (320 up to 6,250 atoms).
void expectParts(const std::vector<mfr::Object>& objects, const RefParts& expected, std::size_t perSphere,
                 const std::string& nameSuffix = "") {
  const std::size_t verticesPerSphere = perSphere / 2 + 2;
  ASSERT_EQ(objects.size(), expected.size());
  bool sawOxygen = false;
  for (std::size_t p = 0; p < objects.size(); ++p) {
    const auto& [name, atoms] = expected[p];
    const mfr::Object& object = objects[p];
    SCOPED_TRACE(name);
    EXPECT_EQ(object.name, name + nameSuffix);
    const mfr::Mesh& mesh = *object.mesh;
    ASSERT_EQ(mesh.triangleCount(), atoms.size() * perSphere);
    ASSERT_EQ(mesh.positions.size(), atoms.size() * verticesPerSphere);
    ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
    EXPECT_NO_THROW(mesh.validate(name));
    mfr::Bounds bounds;
    for (std::size_t s = 0; s < atoms.size(); ++s) {
      const RefAtom& atom = atoms[s];
      const auto look = elements().find(atom.element);
      const std::size_t first = s * verticesPerSphere;
      ASSERT_NE(look, elements().end()) << "element '" << atom.element << "' is not in the test's table";
      const double r = look->second.radius;
      bounds.extend(atom.position - glm::dvec3(r));
      bounds.extend(atom.position + glm::dvec3(r));
      for (std::size_t k = first; k < first + verticesPerSphere; ++k) {
        const glm::dvec3 offset = glm::dvec3(mesh.positions[k]) - atom.position;
        ASSERT_NEAR(glm::length(offset), r, 2e-4) << "sphere " << s << " (" << atom.element << ")";
        ASSERT_NEAR(glm::length(mesh.normals[k]), 1.0f, 1e-5f);
        ASSERT_GT(glm::dot(glm::dvec3(mesh.normals[k]), offset / r), 1.0 - 1e-4) << "normal not radial, sphere " << s;
        ASSERT_EQ(mesh.colors[k], rgba(look->second.rgb)) << "sphere " << s << " (" << atom.element << ")";
      }
      if (atom.hasFields) {
        // Every vertex of the sphere carries its atom's B-factor, occupancy and residue number.
        ASSERT_EQ(mesh.fields.size(), 3u);
        ASSERT_EQ(mfr::fieldNames(mesh), (std::vector<std::string>{"b_factor", "occupancy", "residue"}));
        for (std::size_t k = first; k < first + verticesPerSphere; ++k) {
          ASSERT_EQ(mesh.fields[0].values[k], atom.bFactor) << "b_factor of sphere " << s;
          ASSERT_EQ(mesh.fields[1].values[k], atom.occupancy) << "occupancy of sphere " << s;
          ASSERT_EQ(mesh.fields[2].values[k], atom.residue) << "residue of sphere " << s;
        }
      }
      if (!sawOxygen && atom.element == "O") {
        sawOxygen = true;  // the first oxygen is red: (255, 13, 13)
        EXPECT_EQ(mesh.colors[first], glm::vec4(1.0f, 13.0f / 255.0f, 13.0f / 255.0f, 1.0f));
      }
    }
    const mfr::Bounds b = mesh.bounds();
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(b.min[k], bounds.min[k], 2e-4) << "axis " << k;
      EXPECT_NEAR(b.max[k], bounds.max[k], 2e-4) << "axis " << k;
    }
  }
  EXPECT_TRUE(sawOxygen);
}

std::size_t atomCount(const RefParts& parts) {
  std::size_t n = 0;
  for (const auto& [name, atoms] : parts) n += atoms.size();
  return n;
}

std::vector<std::pair<std::string, std::size_t>> counts(const RefParts& parts) {
  std::vector<std::pair<std::string, std::size_t>> out;
  for (const auto& [name, atoms] : parts) out.emplace_back(name, atoms.size());
  return out;
}

using Counts = std::vector<std::pair<std::string, std::size_t>>;

// ---- PDB (pymol-data) -------------------------------------------------------------------------

TEST(Molecules, Pdb1tii) {
  const fs::path p = requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data");
  const RefParts ref = readPdb(readTestFile(p));
  // 5684 ATOM/HETATM records (grep -c), no altlocs, chains D–H first in the file, waters with a
  // blank chain ID.
  EXPECT_EQ(counts(ref), (Counts{{"chain D", 740},
                                 {"chain E", 740},
                                 {"chain F", 740},
                                 {"chain G", 740},
                                 {"chain H", 740},
                                 {"chain A", 1479},
                                 {"chain C", 290},
                                 {"water", 215}}));
  ASSERT_EQ(atomCount(ref), 5684u);
  const auto start = std::chrono::steady_clock::now();
  const auto objects = mfr::loadModel(p);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  expectParts(objects, ref, 320);  // 5684 × 320 = 1,818,880 triangles, under the 2 M cap
  RecordProperty("load_seconds", std::to_string(seconds));
}

TEST(Molecules, PdbIl2WithHydrogensAndBlankChain) {
  const fs::path p = requireFile(kPymolDemo / "il2.pdb", "Debian package pymol-data");
  const RefParts ref = readPdb(readTestFile(p));
  EXPECT_EQ(counts(ref), (Counts{{"chain (blank)", 2084}}));
  const auto objects = mfr::loadModel(p);
  expectParts(objects, ref, 320);
  std::size_t hydrogens = 0;
  for (const RefAtom& a : ref[0].second) hydrogens += a.element == "H";
  EXPECT_EQ(hydrogens, 1059u);  // kept, each a white sphere (checked above)
}

// An older file: entry ID and line numbers in columns 73–80 where the element and charge are now.
TEST(Molecules, Pdb1hpvLigandWithoutElementColumns) {
  const fs::path p = requireFile("/usr/share/pymol/data/tut/1hpv.pdb", "Debian package pymol-data");
  const RefParts ref = readPdb(readTestFile(p));
  EXPECT_EQ(counts(ref), (Counts{{"chain A", 758}, {"chain B", 758}, {"ligands", 35}, {"water", 80}}));
  expectParts(mfr::loadModel(p), ref, 320);
}

// ---- mmCIF and PDB of the same entries (python-biopython-doc) -------------------------------------

TEST(Molecules, Mmcif4cupLigandsWaterAltlocs) {
  const fs::path p = requireFile(kBiopython / "4CUP.cif.gz", "Debian package python-biopython-doc");
  const RefParts ref = readMmcif(readTestFile(p));
  // 1107 _atom_site rows, 13 of them a second alternative location.
  EXPECT_EQ(counts(ref), (Counts{{"chain A", 924}, {"ligands", 24}, {"water", 146}}));
  expectParts(mfr::loadModel(p), ref, 320);
}

// 2BEG is an NMR ensemble: 10 models of 1855 atoms in the mmCIF, model 1 alone in the PDB file.
TEST(Molecules, Mmcif2begFirstOfTenModelsEqualsThePdb) {
  const fs::path cif = requireFile(kBiopython / "2BEG.cif.gz", "Debian package python-biopython-doc");
  const fs::path pdb = requireFile(kBiopython / "2BEG.pdb.gz", "Debian package python-biopython-doc");
  const RefParts ref = readMmcif(readTestFile(cif));
  EXPECT_EQ(counts(ref),
            (Counts{{"chain A", 371}, {"chain B", 371}, {"chain C", 371}, {"chain D", 371}, {"chain E", 371}}));
  EXPECT_EQ(counts(readPdb(readTestFile(pdb))), counts(ref));
  const auto fromCif = mfr::loadModel(cif);
  expectParts(fromCif, ref, 320, " (model 1 of 10)");
  const auto fromPdb = mfr::loadModel(pdb);
  expectParts(fromPdb, readPdb(readTestFile(pdb)), 320);
  ASSERT_EQ(fromCif.size(), fromPdb.size());
  for (std::size_t i = 0; i < fromCif.size(); ++i) {
    ASSERT_EQ(fromCif[i].mesh->positions.size(), fromPdb[i].mesh->positions.size());
    for (std::size_t k = 0; k < fromCif[i].mesh->positions.size(); ++k)
      ASSERT_NEAR(glm::length(fromCif[i].mesh->positions[k] - fromPdb[i].mesh->positions[k]), 0.0f, 2e-3f);
    EXPECT_EQ(fromCif[i].mesh->colors, fromPdb[i].mesh->colors);
  }
}

// 1A8O: selenomethionines (MSE, HETATM records) belong to the chain, not the ligands.
TEST(Molecules, Mmcif1a8oModifiedResiduesStayInTheChain) {
  const fs::path cif = requireFile(kBiopython / "1A8O.cif.gz", "Debian package python-biopython-doc");
  const fs::path pdb = requireFile(kBiopython / "1A8O.pdb.gz", "Debian package python-biopython-doc");
  const RefParts ref = readMmcif(readTestFile(cif));
  EXPECT_EQ(counts(ref), (Counts{{"chain A", 556}, {"water", 88}}));
  EXPECT_EQ(counts(readPdb(readTestFile(pdb))), counts(ref));
  expectParts(mfr::loadModel(cif), ref, 320);
  expectParts(mfr::loadModel(pdb), readPdb(readTestFile(pdb)), 320);
}

// ---- damaged copies ---------------------------------------------------------------------------

class DamagedMolecules : public mfr::test::TempDirTest {};

TEST_F(DamagedMolecules, TruncatedCorruptAndEmptied) {
  const std::string pdb = readTestFile(requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data"));
  ASSERT_FALSE(pdb.empty());
  // Cut in the middle of a record halfway through the coordinates.
  const std::size_t middle = pdb.find("\nATOM", (pdb.find("\nATOM") + pdb.rfind("\nATOM")) / 2) + 1 + 35;
  expectLoadError(write("1tii-cut.pdb", pdb.substr(0, middle)),
                  "truncated file: the last ATOM/HETATM record ends at column 35");
  // Every coordinate record removed.
  std::string header;
  std::istringstream in(pdb);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("ATOM", 0) != 0 && line.rfind("HETATM", 0) != 0) header += line + "\n";
  expectLoadError(write("1tii-header.pdb", header), "no atoms");

  const std::string cif = readTestFile(requireFile(kBiopython / "4CUP.cif.gz", "Debian package python-biopython-doc"));
  ASSERT_FALSE(cif.empty());
  const std::size_t row = cif.find("\nATOM", (cif.find("\nATOM") + cif.rfind("\nHETATM")) / 2) + 1 + 30;
  expectLoadError(write("4cup-cut.cif", cif.substr(0, row)),
                  "Wrong number of values in the loop (truncated or corrupt?)");
  // A coordinate that is no number.
  const std::size_t x = cif.find("\nATOM");
  std::istringstream first(cif.substr(x + 1, cif.find('\n', x + 1) - x - 1));
  std::vector<std::string> fields{std::istream_iterator<std::string>(first), {}};
  ASSERT_GT(fields.size(), 12u);
  std::string nan = cif;
  const std::size_t xAt = nan.find(" " + fields[10] + " ", x);
  nan.replace(xAt + 1, fields[10].size(), "nan");
  expectLoadError(write("4cup-nan.cif", nan), "not finite");
}

// Atoms held twice, and atoms of no known element, were drawn without a word, with bonds missing
// around them; a cartoon was refused over CA atoms of element X ("needs Cα atoms", a bug hunt).
// Both are notes now, and backbone atoms are taken by their names.
TEST_F(DamagedMolecules, RepeatedAtomsAndUnknownElementsAreNoted) {
  const std::string pdb = readTestFile(requireFile(kPymolDemo / "pept.pdb", "Debian package pymol-data"));
  std::string atoms, unknown;
  std::istringstream in(pdb);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("ATOM", 0) != 0) continue;
    atoms += line + "\n";
    if (line.size() < 78) line.resize(78, ' ');
    unknown += line.substr(0, 76) + "XX\n";  // the element column
  }
  const std::size_t count = static_cast<std::size_t>(std::count(atoms.begin(), atoms.end(), '\n'));
  ASSERT_GT(count, 50u);
  const auto notesOf = [&](const std::string& file, const std::string& text, const char* style) {
    std::vector<std::string> notes;
    mfr::LoadOptions options({}, mfr::MoleculeStyle::parse(style, "test"));
    options.notes = &notes;
    (void)mfr::loadModel(write(file, text), options);
    return notes;
  };
  EXPECT_TRUE(notesOf("pept.pdb", atoms, "sticks").empty());
  const std::vector<std::string> twice = notesOf("twice.pdb", atoms + atoms, "sticks");
  ASSERT_EQ(twice.size(), 1u);
  EXPECT_NE(twice[0].find(std::to_string(count) + " atoms at the position of another atom"), std::string::npos)
      << twice[0];
  const std::vector<std::string> x = notesOf("x.pdb", unknown, "cartoon");
  ASSERT_EQ(x.size(), 1u);
  EXPECT_NE(x[0].find(std::to_string(count) + " atoms of no known element"), std::string::npos) << x[0];
}

// ---- rendering: the exact fragment lists of a structure ------------------------------------------

// Space-filling atoms are a deep scene: along a ray through the protein, the front and back of
// many overlapping spheres.
TEST(Molecules, OracleSeesManyLayers) {
  const fs::path p = requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data");
  const mfr::Scene scene = mfr::loadScene(p);
  const auto start = std::chrono::steady_clock::now();
  const mfr::FragmentLists lists = mfr::castFragments(scene, scene.view("fit"), 48, 48);
  RecordProperty("oracle_seconds",
                 std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
  std::size_t covered = 0;
  for (const std::uint32_t n : lists.counts()) covered += n > 0;
  EXPECT_GE(lists.maxCount(), 4u);
  EXPECT_GT(covered, 48u * 48u / 5) << "the structure covers part of the image";
  RecordProperty("max_depth_complexity", std::to_string(lists.maxCount()));
}

}  // namespace
