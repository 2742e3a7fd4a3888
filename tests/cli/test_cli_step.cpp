// mfr on STEP files, end to end: a bad file gives one line naming it, a non-zero exit and no
// output file (Open CASCADE's own messages must not reach the terminal); a real CAD part renders
// with the oracle and with a GPU method alike, with more than one fragment in some pixels.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kLinkrods = "/usr/share/opencascade/data/step/linkrods.step";
const fs::path kScrew = "/usr/share/opencascade/data/step/screw.step";

using mfr::test::CliResult;
using mfr::test::runCli;

class CliStep : public mfr::test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    if (!fs::exists(kLinkrods) || !fs::exists(kScrew))
      ADD_FAILURE() << "missing the occt-misc STEP samples (scripts/setup installs them)";
  }
  void expectOneLineFailure(const CliResult& r, const std::string& mention) {
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_EQ(r.out.rfind("mfr: ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find(mention), std::string::npos) << r.out;
  }
};

TEST_F(CliStep, BadFilesFailWithOneLine) {
  std::ifstream in(kScrew, std::ios::binary);
  const std::string screw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path cut = write("cut.step", screw.substr(0, screw.size() / 3));
  const fs::path junk = write("junk.stp", "ISO-10303-21;\nthis is not STEP at all\n");
  for (const fs::path& bad : {cut, junk}) {
    SCOPED_TRACE(bad.filename().string());
    expectOneLineFailure(runCli("info " + bad.string()), bad.string() + ": not a readable STEP file");
    const fs::path png = dir() / "out.png";
    expectOneLineFailure(runCli("render " + bad.string() + " -s 16x16 -o " + png.string()), bad.string());
    EXPECT_FALSE(fs::exists(png)) << "partial output left behind";
  }
}

TEST_F(CliStep, LinkrodsRendersWithOracleAndGpu) {
  const fs::path json = dir() / "info.json", oracle = dir() / "oracle.png", gpu = dir() / "gpu.png",
                 stats = dir() / "stats.json";
  CliResult r = runCli("info " + kLinkrods.string() + " -s 48x48 --view iso --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  std::ifstream in(json);
  const nlohmann::json info = nlohmann::json::parse(in);
  EXPECT_EQ(info.at("parts"), 1);
  EXPECT_GT(info.at("triangles").get<int>(), 100);
  // Seen through, a solid is entered and left: two or more fragments in some pixels.
  EXPECT_GE(info.at("depth_complexity").at("max").get<int>(), 2);

  ASSERT_EQ(
      runCli("render " + kLinkrods.string() + " -s 48x48 --view iso --opacity 0.4 -o " + oracle.string()).exitCode, 0);
  r = runCli("render " + kLinkrods.string() + " -s 48x48 --view iso --opacity 0.4 -m abuffer-ll -o " + gpu.string() +
             " --stats " + stats.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const mfr::ImageRGBA8 a = mfr::readPng(oracle), b = mfr::readPng(gpu);
  int covered = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const std::uint8_t* p = a.at(x, y);
      if (p[0] < 250 || p[1] < 250 || p[2] < 250) ++covered;
    }
  EXPECT_GT(covered, 48 * 48 / 20) << "the part covers some of the image";
  EXPECT_LT(covered, 48 * 48) << "and not all of it";
  std::ifstream statsIn(stats);
  const nlohmann::json s = nlohmann::json::parse(statsIn);
  // More fragments than covered pixels: some pixel holds two or more.
  EXPECT_GT(s.at("fragments_stored").get<int>(), covered);
  r = runCli("compare " + oracle.string() + " " + gpu.string() + " --metric rmse");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_LT(std::stod(r.out.substr(r.out.find("rmse ") + 5)), 0.02) << r.out;
}

}  // namespace
