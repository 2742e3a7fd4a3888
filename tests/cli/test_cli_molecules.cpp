// mfr on molecular structures (pymol-data, shared/DATA.md), end to end: info counts the parts and
// triangles, the oracle draws the structure, a GPU method with --opacity agrees with the oracle on
// the per-vertex element colours, and a damaged file is one line and a non-zero exit.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "mfr/image.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int exitCode = -1;
  std::string out;  // stdout + stderr
};

Result run(const std::string& args) {
  Result r;
  const std::string cmd = std::string(MFR_CLI) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return r;
}

const fs::path k1tii = "/usr/share/pymol/data/demo/1tii.pdb";
const fs::path kPept = "/usr/share/pymol/data/demo/pept.pdb";

class CliMolecules : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mfr-cli-mol-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    for (const fs::path& p : {k1tii, kPept})
      if (!fs::exists(p)) ADD_FAILURE() << "missing " << p << " (Debian package pymol-data; scripts/setup installs it)";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(CliMolecules, InfoCountsPartsAndTriangles) {
  const Result r = run("info " + k1tii.string() + " --size 32x32");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  // Chains D–H, A, C (file order) and the waters; 5684 atoms × 320 triangles.
  EXPECT_NE(r.out.find("parts      8\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("triangles  1818880\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 0: chain D (236800 triangles, rgba 1 1 1 0.5)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 5: chain A (473280 triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 7: water (68800 triangles"), std::string::npos) << r.out;
}

TEST_F(CliMolecules, OracleDrawsTheStructure) {
  const fs::path png = dir_ / "1tii.png";
  const Result r = run("render " + k1tii.string() + " --method oracle --size 40x40 -o " + png.string());
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
  const fs::path a = dir_ / "oracle.png", b = dir_ / "gpu.png";
  ASSERT_EQ(run("render " + kPept.string() + " --opacity 0.3 --size 64x48 --method oracle -o " + a.string()).exitCode,
            0);
  const Result g =
      run("render " + kPept.string() + " --opacity 0.3 --size 64x48 --method abuffer-sbuffer -o " + b.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  const Result r = run("compare " + a.string() + " " + b.string() + " --metric rmse");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const double e = std::stod(r.out.substr(r.out.find("rmse ") + 5));
  EXPECT_LT(e, 0.02) << r.out;
  // And the opacity took effect: the same render at opacity 1 differs.
  const fs::path c = dir_ / "opaque.png";
  ASSERT_EQ(run("render " + kPept.string() + " --opacity 1 --size 64x48 --method oracle -o " + c.string()).exitCode, 0);
  const Result d = run("compare " + a.string() + " " + c.string() + " --metric rmse");
  EXPECT_GT(std::stod(d.out.substr(d.out.find("rmse ") + 5)), 0.02) << d.out;
}

TEST_F(CliMolecules, DamagedFileIsOneLine) {
  std::ifstream in(k1tii, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path bad = dir_ / "bad.pdb";
  std::ofstream(bad, std::ios::binary) << text.substr(0, text.find("\nATOM", text.size() / 3) + 20);
  for (const std::string& command :
       {"info " + bad.string(), "render " + bad.string() + " -o " + (dir_ / "x.png").string()}) {
    const Result r = run(command);
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_EQ(r.out.rfind("mfr: " + bad.string() + ": truncated file", 0), 0u) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
  const fs::path smallMolecule = dir_ / "salt.cif";
  std::ofstream(smallMolecule) << "data_nacl\nloop_\n_atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n"
                                  "_atom_site_fract_z\nNa1 0 0 0\nCl1 0.5 0.5 0.5\n";
  const Result r = run("info " + smallMolecule.string());
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("salt.cif: a small-molecule CIF"), std::string::npos) << r.out;
}

}  // namespace
