// mfr on molecular structures (pymol-data, shared/DATA.md), end to end: info counts the parts and
// triangles, the atoms and bonds; the oracle draws the structure, a GPU method with --opacity agrees
// with the oracle on the per-vertex element colours, in every representation (--molecule); a bad
// representation and a damaged file are one line and a non-zero exit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

const fs::path k1tii = "/usr/share/pymol/data/demo/1tii.pdb";
const fs::path kPept = "/usr/share/pymol/data/demo/pept.pdb";

class CliMolecules : public mfr::test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    for (const fs::path& p : {k1tii, kPept})
      if (!fs::exists(p)) ADD_FAILURE() << "missing " << p << " (Debian package pymol-data; scripts/setup installs it)";
  }
};

TEST_F(CliMolecules, InfoCountsPartsAndTriangles) {
  const CliResult r = runCli("info " + k1tii.string() + " --size 32x32");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  // Chains D–H, A, C (file order) and the waters; 5684 atoms × 320 triangles.
  EXPECT_NE(r.out.find("parts      8\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("triangles  1818880\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 0: chain D (236800 triangles, rgba 1 1 1 0.5)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 5: chain A (473280 triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 7: water (68800 triangles"), std::string::npos) << r.out;
}

TEST_F(CliMolecules, OracleDrawsTheStructure) {
  const fs::path png = dir() / "1tii.png";
  const CliResult r = runCli("render " + k1tii.string() + " --method oracle --size 40x40 -o " + png.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const mfr::ImageRGBA8 img = mfr::readPng(png);
  int drawn = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint8_t* c = img.at(x, y);
      drawn += c[0] + c[1] + c[2] < 3 * 250;  // not the white background
    }
  EXPECT_GT(drawn, 40 * 40 / 5) << "pixels drawn";
}

// The element colours (per vertex) and --opacity (the material's alpha) reach a GPU method exactly
// as they reach the oracle.
TEST_F(CliMolecules, GpuAndOracleAgreeWithOpacity) {
  const fs::path a = dir() / "oracle.png", b = dir() / "gpu.png";
  ASSERT_EQ(
      runCli("render " + kPept.string() + " --opacity 0.3 --size 64x48 --method oracle -o " + a.string()).exitCode, 0);
  const CliResult g =
      runCli("render " + kPept.string() + " --opacity 0.3 --size 64x48 --method abuffer-sbuffer -o " + b.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  const CliResult r = runCli("compare " + a.string() + " " + b.string() + " --metric rmse");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const double e = std::stod(r.out.substr(r.out.find("rmse ") + 5));
  EXPECT_LT(e, 0.02) << r.out;
  // And the opacity took effect: the same render at opacity 1 differs.
  const fs::path c = dir() / "opaque.png";
  ASSERT_EQ(runCli("render " + kPept.string() + " --opacity 1 --size 64x48 --method oracle -o " + c.string()).exitCode,
            0);
  const CliResult d = runCli("compare " + a.string() + " " + c.string() + " --metric rmse");
  EXPECT_GT(std::stod(d.out.substr(d.out.find("rmse ") + 5)), 0.02) << d.out;
}

// 107 atoms (the file's ATOM records) and 112 bonds: the count Open Babel finds for the same atoms
// (tests/data MoleculeBonds compares them bond for bond) and PyMOL's own (len(cmd.get_model().bond)).
TEST_F(CliMolecules, InfoCountsAtomsAndBonds) {
  const fs::path json = dir() / "info.json";
  const CliResult r =
      runCli("info " + kPept.string() + " --molecule sticks,surface --no-histogram --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("molecule   107 atoms, 112 bonds; drawn as sticks,surface\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 0: chain E sticks"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 1: chain E surface"), std::string::npos) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("molecule").at("atoms"), 107);
  EXPECT_EQ(j.at("molecule").at("bonds"), 112);
  EXPECT_EQ(j.at("molecule").at("representations"), "sticks,surface");
  EXPECT_EQ(j.at("part_list").at(1).at("closed"), true);  // the surface
  // The β-hairpin's secondary structure by DSSP (no HELIX/SHEET records): mkdssp's 9 strand
  // residues of 13 (tests/data SecondaryStructureAsMkdssp compares them residue by residue).
  EXPECT_NE(r.out.find("13 polymer residues: 0 helix, 9 strand (DSSP, from the backbone)"), std::string::npos) << r.out;
  const nlohmann::json& ss = j.at("molecule").at("secondary_structure");
  EXPECT_EQ(ss.at("source"), "dssp");
  const std::string letters = ss.at("chains").at("chain E");
  EXPECT_EQ(letters.size(), 13u);
  EXPECT_EQ(std::count(letters.begin(), letters.end(), 'E'), 9);
}

// Every representation reaches a GPU method as it reaches the oracle, and each draws differently.
TEST_F(CliMolecules, RepresentationsGpuAndOracleAgree) {
  std::vector<mfr::ImageRGBA8> oracles;
  for (const std::string style : {"spheres", "sticks", "ball-and-stick", "surface,sticks", "cartoon"}) {
    SCOPED_TRACE(style);
    const fs::path a = dir() / "oracle.png", b = dir() / "gpu.png";
    const std::string common = "render " + kPept.string() + " --molecule " + style + " --size 64x48 --view iso ";
    const CliResult o = runCli(common + "--method oracle -o " + a.string());
    ASSERT_EQ(o.exitCode, 0) << o.out;
    const CliResult g = runCli(common + "--method abuffer-sbuffer -o " + b.string());
    ASSERT_EQ(g.exitCode, 0) << g.out;
    const CliResult r = runCli("compare " + a.string() + " " + b.string() + " --metric rmse");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_LT(std::stod(r.out.substr(r.out.find("rmse ") + 5)), 0.02) << r.out;
    oracles.push_back(mfr::readPng(a));
  }
  for (std::size_t i = 0; i < oracles.size(); ++i)
    for (std::size_t k = i + 1; k < oracles.size(); ++k)
      EXPECT_NE(oracles[i].pixels, oracles[k].pixels) << i << " " << k;
}

// A representation drawn on no part (pept.pdb has no ligands) is a note on stderr, the render goes
// on and its output is written; one drawn on nothing at all fails.
TEST_F(CliMolecules, ARepresentationDrawnOnNoPartIsANote) {
  const fs::path out = dir() / "note.png";
  const CliResult r = runCli("render " + kPept.string() +
                             " --molecule cartoon,sticks@ligands --size 32x24 --method oracle -o " + out.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("note: " + kPept.string() + ": no sticks drawn (the structure has no ligands)"),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(fs::exists(out));
  const CliResult none = runCli("render " + kPept.string() + " --molecule sticks@ligands -o " + out.string());
  EXPECT_EQ(none.exitCode, 1) << none.out;
  EXPECT_NE(none.out.find("nothing to draw as sticks@ligands"), std::string::npos) << none.out;
}

class CliMoleculeRefusals : public mfr::test::CliTest {};

TEST_F(CliMoleculeRefusals, BadRepresentationOrNotAMolecule) {
  expectCleanFailure("render " + kPept.string() + " --molecule ribbon",
                     "--molecule ribbon: unknown representation 'ribbon'");
  expectCleanFailure("render " + kPept.string() + " --molecule ,", "--molecule ,: expected spheres");
  expectCleanFailure("render @sample --molecule sticks", "can be chosen only for a molecule file");
  const CliResult info = runCli("info @sample --molecule sticks");
  EXPECT_EQ(info.exitCode, 1) << info.out;
  EXPECT_NE(info.out.find("@sample: a molecule representation (sticks) can be chosen only for a molecule file"),
            std::string::npos)
      << info.out;
  // Atoms piled up at one point: spheres still load, info says why it counts no bonds, sticks are
  // refused (a surface is drawn: the pile's is one sphere).
  std::string pile;
  for (int i = 1; i <= 100; ++i) {
    char line[96];
    std::snprintf(line, sizeof line, "HETATM%5d  C   LIG A   1       1.000   2.000   3.000  1.00 20.00           C  \n",
                  i);
    pile += line;
  }
  const fs::path piled = write("pile.pdb", pile + "END\n");
  const CliResult pileInfo = runCli("info " + piled.string() + " --no-histogram");
  EXPECT_EQ(pileInfo.exitCode, 0) << pileInfo.out;
  EXPECT_NE(pileInfo.out.find("molecule   atoms and bonds not counted: " + piled.string() +
                              ": bonds: 100 atoms in one cube of 1.9 Å: packed denser than any molecule"),
            std::string::npos)
      << pileInfo.out;
  expectCleanFailure("render " + piled.string() + " --molecule sticks", "packed denser than any molecule");
  // probe and bench read it too.
  const CliResult probe = runCli("probe " + kPept.string() + " --molecule sticks --size 64x48 --pixel 32,24");
  EXPECT_EQ(probe.exitCode, 0) << probe.out;
  EXPECT_NE(probe.out.find("chain E"), std::string::npos) << probe.out;
  const CliResult bench =
      runCli("bench " + kPept.string() + " --molecule surface --size 32x24 --methods abuffer-ll --repeat 1");
  EXPECT_EQ(bench.exitCode, 0) << bench.out;
}

TEST_F(CliMolecules, DamagedFileIsOneLine) {
  std::ifstream in(k1tii, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path bad = write("bad.pdb", text.substr(0, text.find("\nATOM", text.size() / 3) + 20));
  for (const std::string& command :
       {"info " + bad.string(), "render " + bad.string() + " -o " + (dir() / "x.png").string()}) {
    const CliResult r = runCli(command);
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_EQ(r.out.rfind("mfr: " + bad.string() + ": truncated file", 0), 0u) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir() / "x.png"));
  const fs::path smallMolecule = write("salt.cif",
                                       "data_nacl\nloop_\n_atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n"
                                       "_atom_site_fract_z\nNa1 0 0 0\nCl1 0.5 0.5 0.5\n");
  const CliResult r = runCli("info " + smallMolecule.string());
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("salt.cif: a small-molecule CIF"), std::string::npos) << r.out;
}

}  // namespace
