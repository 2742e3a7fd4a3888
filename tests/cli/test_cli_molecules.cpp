// mfr on molecular structures (pymol-data, shared/DATA.md), end to end: info counts the parts and
// triangles, the oracle draws the structure, a GPU method with --opacity agrees with the oracle on
// the per-vertex element colours, and a damaged file is one line and a non-zero exit.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

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
