// mfr render / probe / bench --contour end to end: isosurfaces of the scene's volume become parts
// that every method draws like any other (the GPU agrees with the oracle), the volume is hidden
// unless --keep-volume, a scene with several volumes needs the volume's name, the parts can be
// coloured by a volume field, and bad input fails with one line and no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"
#include "image_compare.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

class CliContour : public mfr::test::CliTest {
 protected:
  nlohmann::json stats(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }
};

TEST_F(CliContour, IsosurfacesAreDrawnByEveryMethodAndHideTheirVolume) {
  const std::string common = "render @volume --view iso --size 96x80 --contour 0.3,0.6";
  const fs::path oracle = dir() / "oracle.png", gpu = dir() / "gpu.png", kept = dir() / "kept.png",
                 plain = dir() / "plain.png", gpuStats = dir() / "gpu.json", keptStats = dir() / "kept.json";
  ASSERT_EQ(runCli(common + " -o " + oracle.string()).exitCode, 0);
  const CliResult g = runCli(common + " -m abuffer-sbuffer -o " + gpu.string() + " --stats " + gpuStats.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  EXPECT_LT(rmseOf(oracle, gpu), 0.01);  // edge pixels only
  // auto is "oit": the volume is hidden, only surfaces are left.
  const nlohmann::json s = stats(gpuStats);
  EXPECT_EQ(s["operation"], "oit");
  // Without --contour the image is another one; with --keep-volume the medium is there again.
  ASSERT_EQ(runCli("render @volume --view iso --size 96x80 --op oit -m abuffer-sbuffer -o " + plain.string()).exitCode,
            0);
  EXPECT_GT(rmseOf(gpu, plain), 0.02);
  ASSERT_EQ(runCli(common + " --keep-volume -m abuffer-sbuffer -o " + kept.string() + " --stats " + keptStats.string())
                .exitCode,
            0);
  EXPECT_EQ(stats(keptStats)["operation"], "volume");
  EXPECT_GT(rmseOf(gpu, kept), 0.004);  // the faint medium (measured 0.0097)
}

TEST_F(CliContour, ProbeNamesTheIsosurfacesAndTheirOpacity) {
  const CliResult r = runCli(
      "probe @volume --view iso --size 96x80 --pixel 48,40 --contour 0.3,0.6 --contour-opacity 0.25 -m abuffer-ll");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("field = 0.3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("field = 0.6"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" 64  front"), std::string::npos) << r.out;  // alpha 0.25 → 64/255
  // --opacity reaches the isosurfaces when --contour-opacity is not given.
  const CliResult o = runCli("probe @volume --view iso --size 96x80 --pixel 48,40 --contour 0.3 --opacity 0.8");
  ASSERT_EQ(o.exitCode, 0) << o.out;
  EXPECT_NE(o.out.find("204  front"), std::string::npos) << o.out;
}

TEST_F(CliContour, ColouredByAVolumeFieldTheyShowTheirValue) {
  // A probe of the isosurface at 0.6 coloured by the volume with grayscale: the field value the
  // probe reads at the fragment is the isosurface's, and the colour a gray.
  const CliResult r = runCli(
      "probe @volume --view iso --size 96x80 --pixel 48,40 --contour 0.6 --color-by @field --color-map grayscale "
      "--color-range 0,1");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const std::size_t at = r.out.find("field = 0.6");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
  EXPECT_NE(line.find("@field 0.600"), std::string::npos) << line;
  EXPECT_NE(line.find("148 148 148"), std::string::npos) << line;  // grayscale at 0.6 (ColorMaps.* check the map)
}

// An isosurface coloured by its own volume is one value, up to float rounding (0.7 ± 6e-8 here):
// that rounding was spread over the whole map, in speckles the oracle and the GPU drew apart
// (RMSE 0.01–0.035, a bug hunt). It is now a constant, drawn in the map's middle colour.
TEST_F(CliContour, ColouredByTheirOwnVolumeTheyAreOneColour) {
  {
    std::ofstream grid(dir() / "ball.vtk");  // distance from the centre, 24³ points over [-1, 1]³
    grid << "# vtk DataFile Version 3.0\nball\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 24 24 24\n"
            "ORIGIN -1 -1 -1\nSPACING "
         << 2.0 / 23 << " " << 2.0 / 23 << " " << 2.0 / 23
         << "\nPOINT_DATA 13824\nSCALARS d float 1\nLOOKUP_TABLE default\n";
    for (int k = 0; k < 24; ++k)
      for (int j = 0; j < 24; ++j)
        for (int i = 0; i < 24; ++i) {
          const double x = -1 + 2.0 * i / 23, y = -1 + 2.0 * j / 23, z = -1 + 2.0 * k / 23;
          grid << std::sqrt(x * x + y * y + z * z) << "\n";
        }
  }
  const std::string ball = (dir() / "ball.vtk").string();
  const CliResult r = runCli("probe " + ball +
                             " --size 64x64 --pixel 32,32 --contour 0.7 --color-by @ball.vtk "
                             "--color-map grayscale -m abuffer-ll");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '@'), 2) << r.out;  // both fragments of the sphere
  std::size_t grays = 0;
  for (std::size_t at = r.out.find("127 127 127 128"); at != std::string::npos;
       at = r.out.find("127 127 127 128", at + 1))
    ++grays;
  EXPECT_EQ(grays, 2u) << r.out;  // grayscale's middle, at opacity 0.5
  // The GPU agrees with the oracle as it does uncoloured (edge pixels only).
  const fs::path oracle = dir() / "o.png", gpu = dir() / "g.png", plainOracle = dir() / "po.png",
                 plainGpu = dir() / "pg.png";
  const std::string common = "render " + ball + " --size 96x96 --contour 0.7 ";
  ASSERT_EQ(runCli(common + "--color-by @ball.vtk -o " + oracle.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + "--color-by @ball.vtk -m abuffer-ll -o " + gpu.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + "-o " + plainOracle.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + "-m abuffer-ll -o " + plainGpu.string()).exitCode, 0);
  EXPECT_LT(rmseOf(oracle, gpu), rmseOf(plainOracle, plainGpu) + 0.002);
}

TEST_F(CliContour, BenchAcceptsIsosurfaces) {
  const fs::path json = dir() / "b.json";
  const CliResult r =
      runCli("bench @volume --view iso --size 64x48 --contour 0.5 -m abuffer-ll --repeat 1 --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_TRUE(fs::exists(json));
}

// Two copies of a 5³ ramp volume in one scene file.
fs::path writeTwoVolumeScene(const fs::path& dir) {
  std::ofstream grid(dir / "ramp.vtk");
  grid << "# vtk DataFile Version 3.0\nramp\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 5 5 5\n"
          "ORIGIN -1 -1 -1\nSPACING 0.5 0.5 0.5\nPOINT_DATA 125\nSCALARS ramp float 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < 125; ++i) grid << i % 5 << "\n";
  grid.close();
  std::ofstream scene(dir / "two.mfrscene");
  scene << R"({"volumes": [{"file": "ramp.vtk", "name": "a"},
                           {"file": "ramp.vtk", "name": "b", "transform": {"translate": [3, 0, 0]}}]})";
  return dir / "two.mfrscene";
}

TEST_F(CliContour, SeveralVolumesNeedTheVolumesName) {
  const fs::path scene = writeTwoVolumeScene(dir());
  expectCleanFailure("render " + scene.string() + " --contour 1.5", "say which, as VOLUME=V1,V2");
  expectCleanFailure("render " + scene.string() + " --contour c=1.5", "no volume 'c' in scene");
  const fs::path out = dir() / "b.png", json = dir() / "b.json";
  const CliResult r = runCli("render " + scene.string() + " --contour b=1.5,2.5 -m abuffer-ll -o " + out.string() +
                             " --stats " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(stats(json)["operation"], "volume");  // volume a is still drawn
  const CliResult info =
      runCli("probe " + scene.string() + " --contour b=1.5 --size 64x64 --view orbit:40:20 --pixel 52,32");
  ASSERT_EQ(info.exitCode, 0) << info.out;
  EXPECT_NE(info.out.find("b = 1.5"), std::string::npos) << info.out;
  // A volume's name may hold '=': the values follow the last one ('a=0.3=1.5' was volume 'a').
  {
    std::ofstream named(dir() / "named.mfrscene");
    named << R"({"volumes": [{"file": "ramp.vtk", "name": "a=0.3"},
                             {"file": "ramp.vtk", "name": "b", "transform": {"translate": [3, 0, 0]}}]})";
  }
  const CliResult eq = runCli("render " + (dir() / "named.mfrscene").string() + " --contour a=0.3=1.5 -s 32x32 -o " +
                              (dir() / "eq.png").string());
  EXPECT_EQ(eq.exitCode, 0) << eq.out;
}

TEST_F(CliContour, LegendShowsTheIsosurfacesMapInTheCorner) {
  const std::string common = "render @volume --view iso --size 240x180 -m abuffer-ll --contour 0.3,0.6 ";
  const mfr::ImageRGBA8 plain = renderedPng(common, "plain.png"),
                        legend = renderedPng(common + "--legend", "legend.png");
  const mfr::test::CornerDifference d = mfr::test::legendCornerDifference(plain, legend);
  EXPECT_EQ(d.elsewhere, 0u);  // the legend stays in its corner
  EXPECT_GT(d.inCorner, 300u);
  // The bar's ends are the isosurfaces' colours: the cool-warm map's published ends, ParaView's
  // (59, 76, 192) and (180, 4, 38) — 0.3 blue, 0.6 red.
  bool blue = false, red = false;
  for (int y = plain.height / 4; y < plain.height; ++y)
    for (int x = plain.width / 2; x < plain.width; ++x) {
      const std::uint8_t* p = legend.at(x, y);
      blue = blue || (p[0] == 59 && p[1] == 76 && p[2] == 192);
      red = red || (p[0] == 180 && p[1] == 4 && p[2] == 38);
    }
  EXPECT_TRUE(blue && red);
  expectCleanFailure("render @volume --legend", "and there is no --contour");
}

// One bar keys one colouring: parts a scene file colours by another map are said in a note (the
// bar showed the first part's map without a word: hunt 32).
TEST_F(CliContour, LegendNotesPartsColouredOtherwise) {
  writeTwoVolumeScene(dir());
  const auto scene = [&](const std::string& name, const std::string& secondMap) {
    std::ofstream out(dir() / name);
    out << R"({"objects": [
      {"name": "p", "primitive": {"type": "box"}, "color_by": {"field": "@a", "map": "viridis", "range": [0, 4]}},
      {"name": "q", "primitive": {"type": "box"}, "transform": {"translate": [0, 0, 0.5]},
       "color_by": {"field": "@a", "map": ")" +
               secondMap + R"(", "range": [0, 4]}}],
      "volumes": [{"file": "ramp.vtk", "name": "a", "visible": false}]})";
    return (dir() / name).string();
  };
  const std::string png = (dir() / "l.png").string();
  CliResult r = runCli("render " + scene("two.mfrscene", "magma") + " --legend -s 120x96 -o " + png);
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("note: --legend: the bar keys @a (viridis); also coloured otherwise: 'q' (@a, magma)\n"),
            std::string::npos)
      << r.out;
  r = runCli("render " + scene("one.mfrscene", "viridis") + " --legend -s 120x96 -o " + png);
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;
}

TEST_F(CliContour, BadInputIsOneLine) {
  expectCleanFailure("render @volume --contour abc", "--contour abc: 'abc' is not a number");
  expectCleanFailure("render @volume --contour 0.3,", "--contour 0.3,");
  // Coincident isosurfaces of one name (a bug hunt: two parts, fighting in depth).
  expectCleanFailure("render @volume --contour 0.3,0.3", "0.3 is given twice");
  expectCleanFailure("render @volume --contour 0.3,0.30000001", "values 0.3 and 0.30000001 are one isosurface");
  expectCleanFailure("render @volume --contour 5", "5 lies outside the open range");
  expectCleanFailure("render @volume --contour nan", "--contour nan");
  expectCleanFailure("render @volume --contour 1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1", "at most 16");
  expectCleanFailure("render @sample --contour 0.5", "has no volume");
  expectCleanFailure("render @volume --contour-opacity 0.5", "--contour-opacity: needs --contour");
  expectCleanFailure("render @volume --keep-volume", "--keep-volume: needs --contour");
  expectCleanFailure("render @volume --contour 0.5 --contour-opacity 2", "--contour-opacity");
  // A value the scene file's "contours" has already (two coincident parts of one name), and
  // --keep-volume where the scene file hides the volume (it was taken and changed nothing): hunt 32.
  writeTwoVolumeScene(dir());
  {
    std::ofstream scene(dir() / "own.mfrscene");
    scene << R"({"name": "own", "volumes": [{"file": "ramp.vtk", "name": "a", "contours": [1.5, 2.5]}]})";
    std::ofstream hidden(dir() / "hidden.mfrscene");
    hidden << R"({"name": "hidden", "objects": [{"primitive": {"type": "box"}, "transform": {"translate": [5, 0, 0]}}],
                 "volumes": [{"file": "ramp.vtk", "name": "a", "visible": false}]})";
  }
  expectCleanFailure("render " + (dir() / "own.mfrscene").string() + " --contour 2.5",
                     "--contour 2.5: scene 'own' has isosurface 'a = 2.5' already");
  const CliResult other = runCli("info " + (dir() / "own.mfrscene").string() + " --contour 2 --no-histogram");
  EXPECT_EQ(other.exitCode, 0) << other.out;
  EXPECT_NE(other.out.find("parts      3"), std::string::npos) << other.out;
  expectCleanFailure("render " + (dir() / "hidden.mfrscene").string() + " --contour 2 --keep-volume",
                     "--keep-volume: scene 'hidden' hides volume 'a' (\"visible\": false): there is nothing to keep "
                     "drawing");
  const CliResult plain = runCli("render " + (dir() / "hidden.mfrscene").string() + " --contour 2 -s 16x16 -o " +
                                 (dir() / "plain.png").string());
  EXPECT_EQ(plain.exitCode, 0) << plain.out;
}

}  // namespace
