// Molecules as sticks, balls and sticks and surfaces (mfr::MoleculeStyle) on a small structure
// written here with textbook geometry — an alanine (N–CA 1.46, CA–C 1.52, C=O 1.23, CA–CB 1.53 Å),
// a methane (C–H 1.09 Å, tetrahedral), a sodium ion and a water (O–H 0.96 Å, 104.5°) — whose 10
// bonds are counted by hand; the bond rule (mfr::perceiveBonds) on hand-placed atoms, case by case;
// the style's names; and every place a style can be given or refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/scene/measure.hpp"
#include "mfr/scene/scene_file.hpp"
#include "poly_alanine.hpp"
#include "test_files.hpp"

namespace mfr::test {
namespace {

std::string record(const char* type, int serial, const char* name, const char* residue, char chain, int seq,
                   const glm::dvec3& p, const char* element) {
  char line[96];
  std::snprintf(line, sizeof line, "%-6s%5d %-4s %3s %c%4d    %8.3f%8.3f%8.3f%6.2f%6.2f          %2s  \n", type, serial,
                name, residue, chain, seq, p.x, p.y, p.z, 1.0, 20.0, element);
  return line;
}

// Chain A: ALA 1 (N, CA, C, O, CB: 4 bonds); ligands: methane (4 bonds) and Na⁺ (none), 20 Å
// away; water (2 bonds), 20 Å the other way.
std::string smallStructure() {
  std::string s;
  const glm::dvec3 ca(0.0, 0.0, 0.0);
  s += record("ATOM", 1, " N  ", "ALA", 'A', 1, ca + glm::dvec3(-1.46, 0.0, 0.0), "N");
  s += record("ATOM", 2, " CA ", "ALA", 'A', 1, ca, "C");
  const glm::dvec3 c = ca + 1.52 * glm::normalize(glm::dvec3(0.5, 0.866, 0.0));
  s += record("ATOM", 3, " C  ", "ALA", 'A', 1, c, "C");
  s += record("ATOM", 4, " O  ", "ALA", 'A', 1, c + glm::dvec3(1.23, 0.0, 0.0), "O");
  s += record("ATOM", 5, " CB ", "ALA", 'A', 1, ca + 1.53 * glm::normalize(glm::dvec3(0.5, -0.5, 0.7)), "C");
  s += "TER\n";
  const glm::dvec3 m(20.0, 0.0, 0.0);
  s += record("HETATM", 6, " C  ", "CH4", 'A', 101, m, "C");
  const double t = 1.09 / std::sqrt(3.0);
  int serial = 7;
  for (const glm::dvec3& d : {glm::dvec3(1, 1, 1), glm::dvec3(1, -1, -1), glm::dvec3(-1, 1, -1), glm::dvec3(-1, -1, 1)})
    s += record("HETATM", serial++, " H  ", "CH4", 'A', 101, m + t * d, "H");
  s += record("HETATM", 11, "NA  ", " NA", 'A', 102, glm::dvec3(20.0, 10.0, 0.0), "NA");
  const glm::dvec3 w(-20.0, 0.0, 0.0);
  const double half = 0.5 * 104.5 * 3.14159265358979 / 180.0;
  s += record("HETATM", 12, " O  ", "HOH", 'A', 201, w, "O");
  s += record("HETATM", 13, " H1 ", "HOH", 'A', 201, w + 0.96 * glm::dvec3(std::sin(half), std::cos(half), 0.0), "H");
  s += record("HETATM", 14, " H2 ", "HOH", 'A', 201, w + 0.96 * glm::dvec3(-std::sin(half), std::cos(half), 0.0), "H");
  return s + "END\n";
}

// `load` must fail with one line that starts with the path and holds `reason`.
template <class F>
void expectFails(const std::filesystem::path& path, const std::string& reason, F load) {
  expectFileError(path, reason, [&] {
    load();
    return std::string("loaded");
  });
}

class MoleculeStyles : public TempDirTest {
 protected:
  std::vector<Object> load(const std::string& style) {
    return loadModel(write("small.pdb", smallStructure()), LoadOptions({}, MoleculeStyle::parse(style, "test")));
  }
};

std::map<std::string, std::size_t> trianglesPerPart(const std::vector<Object>& objects) {
  std::map<std::string, std::size_t> out;
  for (const Object& o : objects) out[o.name] = o.mesh->triangleCount();
  return out;
}

// ---- the bond rule -------------------------------------------------------------------------------

MoleculeAtom atom(int z, glm::dvec3 p) {
  return {0, z, p, 0};
}

TEST(BondRule, CovalentRadiiPlusTolerance) {
  // C–C: bonded below 0.73 + 0.73 + 0.45 = 1.91 Å (gemmi's carbon, Cordero's sp² radius).
  EXPECT_EQ(perceiveBonds({atom(6, {0, 0, 0}), atom(6, {1.89, 0, 0})}).size(), 1u);
  EXPECT_EQ(perceiveBonds({atom(6, {0, 0, 0}), atom(6, {1.93, 0, 0})}).size(), 0u);
  // Closer than 0.4 Å: the same atom twice, or a corrupt file — not a bond.
  EXPECT_EQ(perceiveBonds({atom(6, {0, 0, 0}), atom(6, {0.39, 0, 0})}).size(), 0u);
  // Sulphur (1.05) reaches further: a disulphide at 2.05 Å.
  EXPECT_EQ(perceiveBonds({atom(16, {0, 0, 0}), atom(16, {2.05, 0, 0})}).size(), 1u);
}

TEST(BondRule, AnAtomKeepsNoMoreBondsThanItsElementMakes) {
  // A carbon with five hydrogens around it: its longest bond goes.
  std::vector<MoleculeAtom> a = {atom(6, {0, 0, 0}),    atom(1, {1.00, 0, 0}),  atom(1, {-1.01, 0, 0}),
                                 atom(1, {0, 1.02, 0}), atom(1, {0, -1.03, 0}), atom(1, {0, 0, 1.2})};
  EXPECT_EQ(perceiveBonds(a), (std::vector<Bond>{{0, 1}, {0, 2}, {0, 3}, {0, 4}}));
  // Two hydrogens 0.74 Å apart, each 0.93 Å from an oxygen of its own: the first hydrogen has two
  // bonds, one too many, and drops the one to the other hydrogen although it is the shorter.
  const std::vector<MoleculeAtom> hh = {atom(1, {0, 0.37, 0}), atom(1, {0, -0.37, 0}), atom(8, {0, 1.3, 0}),
                                        atom(8, {0, -1.3, 0})};
  EXPECT_EQ(perceiveBonds(hh), (std::vector<Bond>{{0, 2}, {1, 3}}));
  // An oxygen makes two.
  const std::vector<MoleculeAtom> o = {atom(8, {0, 0, 0}), atom(6, {1.40, 0, 0}), atom(6, {-1.41, 0, 0}),
                                       atom(6, {0, 1.42, 0})};
  EXPECT_EQ(perceiveBonds(o), (std::vector<Bond>{{0, 1}, {0, 2}}));
}

TEST(BondRule, TwoBondsCloserThan45DegreesLoseTheLonger) {
  const double a = 30.0 * 3.14159265358979 / 180.0;
  const std::vector<MoleculeAtom> atoms = {atom(6, {0, 0, 0}), atom(6, {1.5, 0, 0}),
                                           atom(6, {1.6 * std::cos(a), 1.6 * std::sin(a), 0})};
  // The two outer carbons are 0.8 Å apart: bonded to each other as well, by distance.
  EXPECT_EQ(perceiveBonds(atoms), (std::vector<Bond>{{0, 1}, {1, 2}}));
}

// ---- drawing --------------------------------------------------------------------------------------

TEST_F(MoleculeStyles, SticksAreTwoHalfTubesPerBondAndAJointPerAtom) {
  const std::vector<Object> objects = load("sticks");
  // Level 2 (320 triangles a sphere), 16-sided tubes (32 triangles a half bond).
  EXPECT_EQ(trianglesPerPart(objects),
            (std::map<std::string, std::size_t>{{"chain A", 5 * 320 + 2 * 4 * 32},
                                                {"ligands", 6 * 320 + 2 * 4 * 32},  // methane, and Na⁺ as a ball
                                                {"water", 3 * 320 + 2 * 2 * 32}}));
  const Mesh& methane = *objects.at(1).mesh;
  // Every tube vertex lies 0.25 Å from the axis of its bond, between the atom and the bond's middle.
  const glm::dvec3 c(20.0, 0.0, 0.0);
  std::size_t atMiddle = 0;
  for (std::size_t v = 0; v < methane.positions.size(); ++v) {
    const glm::dvec3 p(methane.positions[v]);
    const double fromCarbon = glm::length(p - c);
    // The file holds coordinates to 0.001 Å.
    if (std::abs(fromCarbon - 0.25) < 2e-3) continue;  // the carbon's joint
    // The sodium without bonds: a ball of 23 % of its van der Waals radius (Bondi's 2.27 Å).
    if (std::abs(glm::length(p - glm::dvec3(20.0, 10.0, 0.0)) - 0.23 * 2.27) < 2e-3) continue;
    bool found = false;
    for (const glm::dvec3& d :
         {glm::dvec3(1, 1, 1), glm::dvec3(1, -1, -1), glm::dvec3(-1, 1, -1), glm::dvec3(-1, -1, 1)}) {
      const glm::dvec3 axis = glm::normalize(d), h = c + 1.09 * axis;
      if (std::abs(glm::length(p - h) - 0.25) < 2e-3) found = true;  // a hydrogen's joint
      const double along = glm::dot(p - c, axis);
      const double off = glm::length(p - c - along * axis);
      if (std::abs(off - 0.25) < 2e-3 && (std::abs(along) < 2e-3 || std::abs(along - 1.09) < 2e-3)) found = true;
      if (std::abs(off - 0.25) < 2e-3 && std::abs(along - 0.545) < 2e-3) {
        found = true;
        ++atMiddle;
      }
    }
    EXPECT_TRUE(found) << p.x << " " << p.y << " " << p.z;
  }
  EXPECT_EQ(atMiddle, 4u * 2u * 16u);  // each bond's two half tubes end in a ring of 16 at its middle
  // Half bonds take their atom's colour: the carbon's half grey, the hydrogen's white.
  std::size_t white = 0;
  for (const glm::vec4& col : methane.colors) white += col == glm::vec4(1.0f) ? 1u : 0u;
  EXPECT_EQ(white, 4u * (162u + 32u));  // four hydrogens: joint (162 vertices) and half tube
}

TEST_F(MoleculeStyles, BallAndStickBallsAre23PercentOfVanDerWaals) {
  const std::vector<Object> objects = load("ball-and-stick");
  ASSERT_EQ(objects.size(), 3u);
  const Mesh& chain = *objects[0].mesh;
  // Nitrogen (1.55 Å) at (−1.46, 0, 0): a ball of radius 0.23 · 1.55.
  std::size_t onBall = 0;
  for (const glm::vec3& p : chain.positions)
    if (std::abs(glm::length(glm::dvec3(p) - glm::dvec3(-1.46, 0, 0)) - 0.23 * 1.55) < 1e-3) ++onBall;
  EXPECT_GE(onBall, 162u);
  EXPECT_EQ(chain.triangleCount(), 5u * 320u + 2u * 4u * 32u);
}

TEST_F(MoleculeStyles, SurfaceOfEachPartButWaterClosedAndColouredByTheNearestAtom) {
  const std::vector<Object> objects = load("surface,sticks");
  std::vector<std::string> names;
  for (const Object& o : objects) names.push_back(o.name);
  EXPECT_EQ(names, (std::vector<std::string>{"chain A sticks", "chain A surface", "ligands sticks", "ligands surface",
                                             "water sticks"}));
  const Mesh& surface = *objects[1].mesh;
  const SurfaceMeasures m = measureSurface(surface, glm::dmat4(1.0));
  EXPECT_TRUE(m.closed());
  EXPECT_GT(m.volume, 0.0);
  // Coloured as the atom whose van der Waals sphere is nearest: left of x = −2.9 that is the
  // nitrogen (at x = −1.46, radius 1.55 Å), Jmol's blue #3050F8.
  std::size_t blue = 0;
  for (std::size_t v = 0; v < surface.positions.size(); ++v) {
    const glm::dvec3 p(surface.positions[v]);
    if (p.x < -2.9) {
      EXPECT_EQ(surface.colors[v], glm::vec4(0x30 / 255.0f, 0x50 / 255.0f, 0xF8 / 255.0f, 1.0f));
      ++blue;
    }
  }
  EXPECT_GT(blue, 0u);
  ASSERT_EQ(surface.fields.size(), 3u);
  EXPECT_EQ(surface.fields[0].name, "b_factor");
  EXPECT_EQ(surface.fields[0].values.size(), surface.positions.size());
}

TEST_F(MoleculeStyles, OnlyWaterHasNoSurfaceAndNoCartoon) {
  const auto water = write("water.pdb", record("HETATM", 1, " O  ", "HOH", 'A', 1, {0, 0, 0}, "O") + "END\n");
  expectFails(water, "nothing to draw as surface (the structure has water only; water has no surface)",
              [&] { (void)loadModel(water, LoadOptions({}, MoleculeStyle::parse("surface", "t"))); });
  expectFails(water,
              "nothing to draw as cartoon,surface (the structure has water only; a cartoon needs a run of two "
              "polymer residues with Cα or P atoms; water has no surface)",
              [&] { (void)loadModel(water, LoadOptions({}, MoleculeStyle::parse("cartoon,surface", "t"))); });
}

// Representations limited to some parts: the small structure's water as spheres and its ligands
// as sticks, nothing for its chain; and a part the structure lacks draws nothing.
TEST_F(MoleculeStyles, RepresentationsOnSomePartsOnly) {
  const std::vector<Object> parts = load("spheres@water,sticks@ligands");
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].name, "ligands sticks");
  EXPECT_EQ(parts[1].name, "water spheres");
  // Ligands: methane's joint spheres and 4 bonds, the ion's ball; water: three van der Waals spheres.
  EXPECT_EQ(parts[0].mesh->triangleCount(), 6u * 320u + 4u * 2u * 32u);
  EXPECT_EQ(parts[1].mesh->triangleCount(), 3u * 320u);
  const std::vector<Object> chainOnly = load("sticks@polymer");
  ASSERT_EQ(chainOnly.size(), 1u);
  EXPECT_EQ(chainOnly[0].name, "chain A");
  const auto protein = write("protein.pdb", record("ATOM", 1, " CA ", "ALA", 'A', 1, {0, 0, 0}, "C") + "END\n");
  expectFails(protein, "nothing to draw as sticks@ligands (the structure has polymer chains only)",
              [&] { (void)loadModel(protein, LoadOptions({}, MoleculeStyle::parse("sticks@ligands", "t"))); });
}

// A representation that draws on no part, while others do, is no error but a note naming the file
// and the reason; the scene keeps the notes.
TEST_F(MoleculeStyles, ARepresentationDrawnOnNoPartIsANote) {
  const auto file = write("small.pdb", smallStructure());
  std::vector<std::string> notes;
  LoadOptions options({}, MoleculeStyle::parse("cartoon,sticks@ligands,spheres@water,surface@water", "t"));
  options.notes = &notes;
  const std::vector<Object> parts = loadModel(file, options);
  ASSERT_EQ(parts.size(), 2u);  // the ligands' sticks, the water's spheres
  const std::string path = file.string();
  EXPECT_EQ(notes, (std::vector<std::string>{path + ": no cartoon drawn (no chain has two residues with Cα or P atoms)",
                                             path + ": no surface drawn (water has no surface)"}));
  notes.clear();
  options.molecule = MoleculeStyle::parse("spheres,cartoon@ligands,ball-and-stick@water", "t");
  (void)loadModel(write("ligands.pdb", record("HETATM", 1, " C  ", "CH4", 'A', 1, {0, 0, 0}, "C") + "END\n"), options);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("no ball-and-stick drawn (the structure has no water)"), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("no cartoon drawn (ligands and water have no cartoon)"), std::string::npos) << notes[1];
  notes.clear();
  options.molecule = MoleculeStyle::parse("spheres,cartoon", "t");
  (void)loadModel(write("ligands.pdb", record("HETATM", 1, " C  ", "CH4", 'A', 1, {0, 0, 0}, "C") + "END\n"), options);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("no cartoon drawn (the structure has no polymer chains)"), std::string::npos) << notes[0];
  // Residues with Cα atoms, but none in a row close enough to be bonded; residues without any.
  notes.clear();
  options.molecule = MoleculeStyle::parse("cartoon,spheres", "t");
  (void)loadModel(write("broken.pdb", record("ATOM", 1, " CA ", "ALA", 'A', 1, {0, 0, 0}, "C") +
                                          record("ATOM", 2, " CA ", "ALA", 'A', 2, {10, 0, 0}, "C") +
                                          record("ATOM", 3, " CA ", "ALA", 'A', 3, {20, 0, 0}, "C") + "END\n"),
                  options);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("no cartoon drawn (no chain has two residues in a row that make a backbone: Cα atoms at "
                          "most 4.5 Å apart, or P atoms at most 8 Å apart)"),
            std::string::npos)
      << notes[0];
  notes.clear();
  (void)loadModel(write("no-trace.pdb", record("ATOM", 1, " N  ", "ALA", 'A', 1, {0, 0, 0}, "N") +
                                            record("ATOM", 2, " C  ", "ALA", 'A', 1, {1.4, 0, 0}, "C") + "END\n"),
                  options);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("no cartoon drawn (no polymer residue has a Cα or P atom)"), std::string::npos) << notes[0];
  // Everything drawn: no note. And through loadScene, the scene's notes.
  notes.clear();
  options.molecule = MoleculeStyle::parse("sticks", "t");
  (void)loadModel(file, options);
  EXPECT_TRUE(notes.empty());
  const Scene scene = loadScene(file, LoadOptions({}, MoleculeStyle::parse("cartoon,spheres", "t")));
  ASSERT_EQ(scene.notes.size(), 1u);
  EXPECT_NE(scene.notes[0].find("no cartoon drawn"), std::string::npos);
}

// A file's HELIX/SHEET ranges hold the residues whose numbers lie between their ends, also when an
// end residue is missing from the file (as PyMOL reads them); helix wins where both claim one.
TEST_F(MoleculeStyles, RecordedRangesByResidueNumber) {
  const auto helix = [](int from, int to) {
    char line[96];
    std::snprintf(line, sizeof line, "HELIX  %3d %3s %3s %c %4d%c %3s %c %4d%c%2d\n", 1, "1", "ALA", 'A', from, ' ',
                  "ALA", 'A', to, ' ', 1);
    return std::string(line);
  };
  const auto sheet = [](int from, int to) {
    char line[96];
    std::snprintf(line, sizeof line, "SHEET  %3d %3s%2d %3s %c%4d%c %3s %c%4d%c%2d\n", 1, "S", 1, "ALA", 'A', from, ' ',
                  "ALA", 'A', to, ' ', 0);
    return std::string(line);
  };
  // Residues 1–14 but 5 and 8, Cα only, 3.8 Å apart; helix 2–5 (5 missing), strand 8–10 (8
  // missing), strand 12–13 inside helix 11–13 (helix wins).
  std::string pdb = helix(2, 5) + helix(11, 13) + sheet(8, 10) + sheet(12, 13);
  int serial = 1;
  for (int n = 1; n <= 14; ++n)
    if (n != 5 && n != 8) pdb += record("ATOM", serial++, " CA ", "ALA", 'A', n, {3.8 * n, 0.0, 0.0}, "C");
  const MoleculeStructure m = readMoleculeStructure(write("ranges.pdb", pdb + "END\n"));
  ASSERT_TRUE(m.secondaryStructureFromFile);
  std::string letters;
  for (const BackboneResidue& r : m.residues) letters += secondaryStructureLetter(r.structure);
  // 1 2 3 4 6 7 9 10 11 12 13 14
  EXPECT_EQ(letters, "-HHH--EEHHH-");
}

// Records that hold no residue of the structure (a chain renamed after the header was written)
// are not read as "all loop": DSSP's structure is drawn, and the structure says so. A record that
// holds a residue is taken, and DSSP not run.
TEST_F(MoleculeStyles, RecordsThatHoldNoResidueGiveWayToDssp) {
  std::string atoms;
  int serial = 1;
  for (const BackboneResidue& r : polyAlanine(12, -57.0, -47.0))  // an ideal α-helix
    for (const auto& [name, p, element] : {std::tuple{" N  ", *r.n, "N"}, std::tuple{" CA ", *r.ca, "C"},
                                           std::tuple{" C  ", *r.c, "C"}, std::tuple{" O  ", *r.o, "O"}})
      atoms += record("ATOM", serial++, name, "ALA", 'A', r.number, p, element);
  const auto helixRecord = [](char chain, int from, int to) {
    char line[96];
    std::snprintf(line, sizeof line, "HELIX  %3d %3s %3s %c %4d%c %3s %c %4d%c%2d\n", 1, "1", "ALA", chain, from, ' ',
                  "ALA", chain, to, ' ', 1);
    return std::string(line);
  };
  const auto letters = [](const MoleculeStructure& m) {
    std::string out;
    for (const BackboneResidue& r : m.residues) out += secondaryStructureLetter(r.structure);
    return out;
  };
  const MoleculeStructure renamed = readMoleculeStructure(write("renamed.pdb", helixRecord('Z', 1, 12) + atoms));
  EXPECT_FALSE(renamed.secondaryStructureFromFile);
  EXPECT_TRUE(renamed.secondaryStructureRecordsUnmatched);
  EXPECT_EQ(letters(renamed), "-HHHHHHHHHH-");
  const MoleculeStructure recorded = readMoleculeStructure(write("recorded.pdb", helixRecord('A', 3, 5) + atoms));
  EXPECT_TRUE(recorded.secondaryStructureFromFile);
  EXPECT_FALSE(recorded.secondaryStructureRecordsUnmatched);
  EXPECT_EQ(letters(recorded), "--HHH-------");
}

// A trace that repeats a point or turns straight back is no backbone: the repeated point is left
// out and the run ends at the reversal, so every cartoon tube stays closed.
TEST_F(MoleculeStyles, CartoonSkipsRepeatedPointsAndEndsRunsAtReversals) {
  std::string pdb;
  int serial = 1, number = 1;
  for (const double x : {0.0, 3.8, 3.8, 7.6, 3.8})
    pdb += record("ATOM", serial++, " CA ", "ALA", 'A', number++, {x, 0.0, 0.0}, "C");
  const std::vector<Object> parts =
      loadModel(write("trace.pdb", pdb + "END\n"), LoadOptions({}, MoleculeStyle::parse("cartoon", "t")));
  ASSERT_EQ(parts.size(), 1u);
  // One run of three residues (0, 3.8, 7.6): 17 rings of 16, two caps; the residue after the
  // reversal alone draws nothing.
  EXPECT_EQ(parts[0].mesh->triangleCount(), 16u * 16u * 2u + 2u * 16u);
  EXPECT_TRUE(measureSurface(*parts[0].mesh, glm::dmat4(1.0)).closed());
}

// ---- naming, and where a style may be given -------------------------------------------------------

TEST(MoleculeStyleNames, ParseAndText) {
  EXPECT_EQ(MoleculeStyle{}.text(), "spheres");
  EXPECT_EQ(MoleculeStyle::parse("surface+sticks", "x").text(), "sticks,surface");
  EXPECT_EQ(MoleculeStyle::parse("ball-and-stick,spheres", "x").text(), "spheres,ball-and-stick");
  const auto reason = [](const std::string& text) {
    try {
      (void)MoleculeStyle::parse(text, "--molecule " + text);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(MoleculeStyle::parse("surface,cartoon,sticks", "x").text(), "sticks,cartoon,surface");
  // Limited to some parts: one item per part, in the order polymer, ligands, water; all three is
  // the plain name.
  const MoleculeStyle scoped = MoleculeStyle::parse("cartoon@polymer,sticks@water+sticks@ligands", "x");
  EXPECT_EQ(scoped.text(), "sticks@ligands,sticks@water,cartoon@polymer");
  EXPECT_TRUE(scoped.sticks && !scoped.sticks.polymer && scoped.sticks.ligands && scoped.sticks.water);
  EXPECT_FALSE(scoped.spheres);
  EXPECT_EQ(MoleculeStyle::parse(scoped.text(), "x"), scoped);
  EXPECT_EQ(MoleculeStyle::parse("surface@polymer,surface@ligands,surface@water", "x").text(), "surface");
  EXPECT_EQ(MoleculeStyle::parse("sticks@water,sticks", "x").text(), "sticks");
  EXPECT_EQ(reason("sticks@protein"),
            "--molecule sticks@protein: unknown part 'protein' after 'sticks@': expected polymer, ligands or water");
  EXPECT_EQ(reason("ribbon@ligands"),
            "--molecule ribbon@ligands: unknown representation 'ribbon': expected spheres, sticks, ball-and-stick, "
            "cartoon or surface, joined by ',' (cartoon,sticks@ligands: '@' limits one to polymer, ligands or water)");
  EXPECT_EQ(reason("ribbon"),
            "--molecule ribbon: unknown representation 'ribbon': expected spheres, sticks, ball-and-stick, "
            "cartoon or surface, joined by ',' (cartoon,sticks@ligands: '@' limits one to polymer, ligands or water)");
  // A trailing blank is kept in the quote: 'sticks' read as the valid name (a bug hunt).
  EXPECT_NE(reason("sticks\n").find("unknown representation 'sticks ': "), std::string::npos) << reason("sticks\n");
  EXPECT_EQ(reason("sticks "),
            "--molecule sticks: unknown representation 'sticks ': expected spheres, sticks, ball-and-stick, "
            "cartoon or surface, joined by ',' (cartoon,sticks@ligands: '@' limits one to polymer, ligands or water)");
  EXPECT_EQ(reason(""),
            "--molecule: expected spheres, sticks, ball-and-stick, cartoon or surface, joined by ',' "
            "(cartoon,sticks@ligands: '@' limits one to polymer, ligands or water)");
  EXPECT_EQ(reason("sticks,"),
            "--molecule sticks,: expected spheres, sticks, ball-and-stick, cartoon or surface, joined by ',' "
            "(cartoon,sticks@ligands: '@' limits one to polymer, ligands or water)");
  // Whatever was typed, the message is one short line.
  const std::string multiLine = reason("surface\nsticks");
  EXPECT_EQ(multiLine.find('\n'), std::string::npos) << multiLine;
  EXPECT_EQ(multiLine,
            "--molecule surface sticks: unknown representation 'surface sticks': expected spheres, "
            "sticks, ball-and-stick, cartoon or surface, joined by ',' (cartoon,sticks@ligands: '@' limits one to "
            "polymer, ligands or water)");
  EXPECT_LT(reason(std::string(100'000, 'x')).size(), 300u);
}

// A model file placed several times by a scene file is read once and its meshes shared, as a
// glTF's or STEP's instances are (each object read it again and kept its own copy: 16 placements of
// a 500k-triangle part took 12x the time and 2.6x the memory; a bug hunt). Each placement keeps its
// own transform and colour; other representations of the file are another model.
TEST_F(MoleculeStyles, AModelFilePlacedSeveralTimesSharesItsMeshes) {
  write("small.pdb", smallStructure());
  const auto scene = write("placed.mfrscene", R"({"objects": [
      {"name": "a", "file": "small.pdb", "molecule": "sticks"},
      {"name": "b", "file": "small.pdb", "molecule": "sticks", "color": [1, 0, 0],
       "transform": {"translate": [5, 0, 0]}},
      {"name": "c", "file": "small.pdb", "molecule": "spheres"},
      {"name": "d", "file": "./small.pdb", "molecule": "sticks"}]})");
  const Scene s = loadScene(scene);
  ASSERT_EQ(s.objects.size(), 12u);
  for (std::size_t i = 0; i < 3; ++i) {
    const Object &a = s.objects[i], &b = s.objects[3 + i], &c = s.objects[6 + i], &d = s.objects[9 + i];
    EXPECT_EQ(a.mesh.get(), b.mesh.get()) << i;
    EXPECT_EQ(a.mesh.get(), d.mesh.get()) << i;  // the same file, named another way
    EXPECT_NE(a.mesh.get(), c.mesh.get()) << i;  // spheres, not sticks
    EXPECT_EQ(b.transform[3], glm::dmat4(1.0)[3] + glm::dvec4(5, 0, 0, 0)) << i;
    EXPECT_EQ(a.transform, d.transform) << i;
    EXPECT_EQ(glm::vec3(b.material.color), glm::vec3(1, 0, 0)) << i;
    EXPECT_TRUE(a.material.vertexColors && !b.material.vertexColors) << i;  // b's colour is b's alone
    EXPECT_EQ(a.name.substr(0, 2), "a/");
    EXPECT_EQ(b.name.substr(0, 2), "b/");
  }
  // Links to one file from two folders are two models: each is read through its own name and folder,
  // where its side files lie (an OBJ's mtllib; the second link took the first one's colours: a
  // review). Two names of one folder's file still share.
  namespace fs = std::filesystem;
  fs::create_directories(dir() / "real");
  fs::create_directories(dir() / "red");
  fs::create_directories(dir() / "blue");
  write("real/model.obj", "mtllib model.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paint\nf 1 2 3\n");
  write("red/model.mtl", "newmtl paint\nKd 1 0 0\n");
  write("blue/model.mtl", "newmtl paint\nKd 0 0 1\n");
  fs::create_symlink(dir() / "real/model.obj", dir() / "red/model.obj");
  fs::create_symlink(dir() / "real/model.obj", dir() / "blue/model.obj");
  const Scene linked = loadScene(write("linked.mfrscene", R"({"objects": [
      {"name": "r", "file": "red/model.obj"}, {"name": "b", "file": "blue/model.obj"},
      {"name": "b2", "file": "blue/../blue/model.obj"}]})"));
  ASSERT_EQ(linked.objects.size(), 3u);
  EXPECT_EQ(glm::vec3(linked.objects[0].material.color), glm::vec3(1, 0, 0));
  EXPECT_EQ(glm::vec3(linked.objects[1].material.color), glm::vec3(0, 0, 1));
  EXPECT_EQ(glm::vec3(linked.objects[2].material.color), glm::vec3(0, 0, 1));
  EXPECT_EQ(linked.objects[1].mesh.get(), linked.objects[2].mesh.get());
}

TEST_F(MoleculeStyles, OnlyForMoleculeFiles) {
  const auto stl = write("part.stl", "solid x\nendsolid x\n");
  const LoadOptions sticks({}, MoleculeStyle::parse("sticks", "t"));
  expectFails(stl, "a molecule representation (sticks) can be chosen only for a molecule file (.pdb .ent .cif .mmcif)",
              [&] { (void)loadModel(stl, sticks); });
  const auto scene = write("s.mfrscene", R"({"objects": [{"file": "small.pdb"}]})");
  write("small.pdb", smallStructure());
  expectFails(scene,
              "a molecule representation (sticks) can be chosen only for a molecule file (a scene file gives each "
              "molecule its own 'molecule')",
              [&] { (void)loadScene(scene, sticks); });
  // A scene file's object says it itself.
  const auto own = write("own.mfrscene", R"({"objects": [{"file": "small.pdb", "molecule": "sticks"}]})");
  EXPECT_EQ(loadScene(own).objects.size(), 3u);
  EXPECT_EQ(loadScene(own).objects[0].mesh->triangleCount(), 5u * 320u + 2u * 4u * 32u);
  const auto bad = write("bad.mfrscene", R"({"objects": [{"file": "small.pdb", "molecule": "ribbon"}]})");
  expectFails(bad,
              "objects[0].molecule: unknown representation 'ribbon': expected spheres, sticks, ball-and-stick, "
              "cartoon or surface, joined by ',' (cartoon,sticks@ligands: '@' limits one to polymer, ligands or "
              "water)",
              [&] { (void)loadScene(bad); });
  const auto primitive =
      write("pr.mfrscene", R"({"objects": [{"primitive": {"type": "sphere", "radius": 1}, "molecule": "sticks"}]})");
  expectFails(primitive, "objects[0].molecule: only a molecule file (.pdb .ent .cif .mmcif) has representations",
              [&] { (void)loadScene(primitive); });
  const auto notMolecule = write("nm.mfrscene", R"({"objects": [{"file": "part.stl", "molecule": "sticks"}]})");
  expectFails(notMolecule, "objects[0].molecule: only a molecule file (.pdb .ent .cif .mmcif) has representations",
              [&] { (void)loadScene(notMolecule); });
}

}  // namespace
}  // namespace mfr::test
