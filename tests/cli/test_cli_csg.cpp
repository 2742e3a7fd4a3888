// mfr render --op csg end to end: the built-in CSG sample from the oracle and an A-buffer agree,
// a CSG tree in an .mfrscene file renders, and bad trees, scenes without one and methods that
// cannot carry object ids fail with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

class CliCsg : public mfr::test::CliTest {
 protected:
  fs::path writeScene(const std::string& text) {
    const fs::path p = dir() / "part.mfrscene";
    std::ofstream(p) << text;
    return p;
  }
};

TEST_F(CliCsg, OracleAndGpuAgreeOnTheSample) {
  const fs::path a = dir() / "oracle.png", b = dir() / "gpu.png";
  ASSERT_EQ(runCli("render @csg --op csg --size 80x64 --view iso -o " + a.string()).exitCode, 0);
  const CliResult g = runCli("render @csg --op csg --method abuffer-sbuffer --size 80x64 --view iso -o " + b.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  const CliResult r = runCli("compare " + a.string() + " " + b.string() + " --metric rmse");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_LT(std::stod(r.out.substr(r.out.find("rmse ") + 5)), 0.02) << r.out;  // edge pixels only
  // The block's centre is a solid, opaque surface (not the white background).
  const mfr::ImageRGBA8 img = mfr::readPng(a);
  const std::uint8_t* c = img.at(40, 32);
  EXPECT_LT(int(c[0]) + c[1] + c[2], 3 * 240);
}

// A drilled box from a scene file: the drill's bore shows the background straight through it
// along the drill's axis, where "oit" shows the box.
TEST_F(CliCsg, SceneFileTreeRenders) {
  const fs::path scene = writeScene(R"({
    "objects": [
      {"name": "box", "primitive": {"type": "box", "size": [2, 2, 2]}, "color": [0.7, 0.7, 0.8], "opacity": 1},
      {"name": "drill", "primitive": {"type": "cylinder", "radius": 0.5, "height": 3},
       "transform": {"rotate": [90, 0, 0]}, "color": [0.9, 0.3, 0.3], "opacity": 1}],
    "views": [{"name": "down the drill", "eye": [0.01, 0.02, 6], "target": [0, 0, 0]}],
    "csg": {"difference": ["box", "drill"]}})");
  for (const char* method : {"oracle", "abuffer-ll"}) {
    SCOPED_TRACE(method);
    const fs::path csg = dir() / "csg.png", oit = dir() / "oit.png";
    const std::string common =
        "render " + scene.string() + " --method " + method + " --size 48x48 --view \"down the drill\"";
    const CliResult r = runCli(common + " --op csg -o " + csg.string());
    ASSERT_EQ(r.exitCode, 0) << r.out;
    ASSERT_EQ(runCli(common + " -o " + oit.string()).exitCode, 0);
    // The images kept: pointers into temporaries read freed pixels (a sanitizer run).
    const mfr::ImageRGBA8 csgImage = mfr::readPng(csg), oitImage = mfr::readPng(oit);
    const std::uint8_t* hole = csgImage.at(24, 24);
    EXPECT_EQ(int(hole[0]) + hole[1] + hole[2], 3 * 255);  // background through the bore
    const std::uint8_t* wall = csgImage.at(24, 16);
    EXPECT_LT(int(wall[0]) + wall[1] + wall[2], 3 * 240);  // the box's face
    const std::uint8_t* covered = oitImage.at(24, 24);
    EXPECT_LT(int(covered[0]) + covered[1] + covered[2], 3 * 250);  // "over": the drill's cap
  }
}

// mfr bench with op=csg: the row is labelled with it and measured against the oracle's CSG image
// (against its "over" image the bores would count as errors), the plain row against "over".
TEST_F(CliCsg, BenchMeasuresCsgRowsAgainstTheOraclesCsg) {
  const fs::path json = dir() / "bench.json";
  const CliResult r =
      runCli("bench @csg --view iso --size 96x80 -r 1 -m abuffer-ll,abuffer-ll:op=csg --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["results"].size(), 2u);
  EXPECT_EQ(j["results"][0]["method"], "abuffer-ll");
  EXPECT_EQ(j["results"][1]["method"], "abuffer-ll:op=csg");
  EXPECT_LT(j["results"][0]["rmse"].get<double>(), 0.01);  // opaque solids: "over" is the nearest surface
  EXPECT_LT(j["results"][1]["rmse"].get<double>(), 0.02);  // edge pixels only
  EXPECT_EQ(j["results"][1]["bytes_allocated"].get<std::uint64_t>(),
            j["results"][0]["bytes_allocated"].get<std::uint64_t>() + 8u * 96u * 80u);
}

TEST_F(CliCsg, BadInputIsOneLine) {
  expectCleanFailure("render @sample --op csg", "no CSG tree");
  expectCleanFailure("render @csg --op csg --method kplus-array", "cannot store object ids");
  expectCleanFailure("render @csg --op csg --method optimal-k", "optimal-k");
  const fs::path unknown = writeScene(R"({"objects": [{"name": "box", "primitive": {"type": "box", "size": [1, 1, 1]}}],
                                          "csg": {"union": ["box", "nope"]}})");
  expectCleanFailure("render " + unknown.string() + " --op csg", "nope");
  const fs::path open = writeScene(R"({"objects": [
      {"name": "box", "primitive": {"type": "box", "size": [1, 1, 1]}},
      {"name": "sheet", "primitive": {"type": "plane", "width": 1, "height": 1}}],
    "csg": {"difference": ["box", "sheet"]}})");
  expectCleanFailure("render " + open.string(), "not a closed surface");
}

}  // namespace
