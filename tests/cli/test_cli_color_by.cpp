// --color-by end to end on a VTP sheet with point and cell data: mfr info lists the fields and
// their ranges, the GPU image equals the oracle's, the map and the range show, a pixel of a sheet
// seen head-on is exactly the map's colour, a scene file's "color_by" draws the same image as the
// options, and bad fields, maps and ranges are one line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include <fstream>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/reference/metrics.hpp"
#include "image_compare.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

using CliColorBy = mfr::test::CliTest;

constexpr int kN = 9;  // points per side of the sheet

// A flat sheet of 9 × 9 points over [-2, 2]² at z = 0, facing +Z, as ASCII VTK XML PolyData:
// point data "pressure" = x + y² / 4 (from −2 to 3) and "velocity" (3 components), cell data
// "zone" = 1 on the left half of the quads, 2 on the right.
std::string sheet() {
  std::ostringstream points, pressure, velocity, connectivity, offsets, zone;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) {
      const double x = -2.0 + 4.0 * i / (kN - 1), y = -2.0 + 4.0 * j / (kN - 1);
      points << x << " " << y << " 0 ";
      pressure << x + y * y / 4.0 << " ";
      velocity << y << " " << -x << " 1 ";
    }
  int quads = 0;
  for (int j = 0; j + 1 < kN; ++j)
    for (int i = 0; i + 1 < kN; ++i) {
      const int a = j * kN + i;
      connectivity << a << " " << a + 1 << " " << a + 1 + kN << " " << a + kN << " ";
      offsets << 4 * ++quads << " ";
      zone << (i < (kN - 1) / 2 ? 1 : 2) << " ";
    }
  std::ostringstream s;
  s << R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints=")"
    << kN * kN << R"(" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys=")" << quads << R"(">
      <PointData>
        <DataArray type="Float32" Name="pressure" format="ascii">)"
    << pressure.str() << R"(</DataArray>
        <DataArray type="Float32" Name="velocity" NumberOfComponents="3" format="ascii">)"
    << velocity.str() << R"(</DataArray>
      </PointData>
      <CellData>
        <DataArray type="Int32" Name="zone" format="ascii">)"
    << zone.str() << R"(</DataArray>
      </CellData>
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">)"
    << points.str() << R"(</DataArray>
      </Points>
      <Polys>
        <DataArray type="Int32" Name="connectivity" format="ascii">)"
    << connectivity.str() << R"(</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">)"
    << offsets.str() << R"(</DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
)";
  return s.str();
}

TEST_F(CliColorBy, InfoListsTheFieldsWithTheirRanges) {
  const fs::path file = write("sheet.vtp", sheet());
  const CliResult r = runCli("info " + file.string() + " --no-histogram");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  // velocity:2 is 1 everywhere: the data's own range, not the colour map's widened one.
  EXPECT_NE(r.out.find("fields: pressure [-2, 3] velocity [-2, 2] velocity:1 [-2, 2] velocity:2 [1, 1] "
                       "velocity:magnitude [1, 3] zone (cells) [1, 2]"),
            std::string::npos)
      << r.out;
}

TEST_F(CliColorBy, GpuEqualsOracleAndTheMapAndRangeShow) {
  const fs::path file = write("sheet.vtp", sheet());
  // 60 × 50: no pixel centre lies on the sheet's grid lines (there ray casting and rasterisation
  // may disagree on which triangle the pixel sees: the oracle's edge pixels).
  const std::string common = "render " + file.string() + " --size 60x50 --opacity 0.7 ";
  const auto image = [&](const std::string& args, const std::string& name) {
    const fs::path out = dir() / name;
    const CliResult r = runCli(common + args + " -o " + out.string());
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return mfr::readPng(out);
  };
  const mfr::ImageRGBA8 plain = image("-m abuffer-ll", "plain.png");
  const mfr::ImageRGBA8 gpu = image("-m abuffer-ll --color-by pressure", "gpu.png");
  const mfr::ImageRGBA8 oracle = image("--color-by pressure", "oracle.png");
  const mfr::ImageRGBA8 viridis = image("-m abuffer-ll --color-by pressure --color-map viridis", "viridis.png");
  const mfr::ImageRGBA8 narrow = image("-m abuffer-ll --color-by pressure --color-range 0,1", "narrow.png");
  const mfr::ImageRGBA8 zone = image("-m kplus-array -p k=4 --color-by zone --color-map grayscale", "zone.png");
  const mfr::ImageRGBA8 zoneOracle = image("--color-by zone --color-map grayscale", "zone-oracle.png");
  EXPECT_LT(mfr::rmse(oracle, gpu), 0.01);
  EXPECT_LT(mfr::rmse(zoneOracle, zone), 0.012);  // a few pixels on a diagonal edge differ
  EXPECT_GT(mfr::rmse(plain, gpu), 0.05);
  EXPECT_GT(mfr::rmse(gpu, viridis), 0.05);
  EXPECT_GT(mfr::rmse(gpu, narrow), 0.02);
  // Cell data: the left half of the sheet is the map's low end (black, over the white background
  // at opacity 0.7: 0.3 · 255 ≈ 77), the right half its high end (white).
  EXPECT_NEAR(zone.at(18, 25)[0], 77, 2);
  EXPECT_NEAR(zone.at(42, 25)[0], 255, 1);
  EXPECT_LT(plain.at(42, 25)[0], 240);  // the sheet is there (its grey over the background)
}

TEST_F(CliColorBy, LegendIsDrawnInTheLowerRightCornerOnly) {
  const fs::path file = write("sheet.vtp", sheet());
  const std::string common = "render " + file.string() + " --size 320x240 -m abuffer-ll --color-by pressure ";
  const mfr::ImageRGBA8 plain = renderedPng(common, "plain.png"),
                        legend = renderedPng(common + "--legend", "legend.png");
  const mfr::test::CornerDifference d = mfr::test::legendCornerDifference(plain, legend);
  EXPECT_EQ(d.elsewhere, 0u);  // the legend stays in its corner
  EXPECT_GT(d.inCorner, 500u);
  expectCleanFailure("render " + file.string() + " --legend", "--legend: nothing is coloured by a field");
  expectCleanFailure("render " + file.string() + " --size 64x64 -m abuffer-ll --color-by pressure --legend",
                     "--legend: the image 64x64 is too small");
}

TEST_F(CliColorBy, AHeadOnPixelIsExactlyTheMapsColour) {
  // Opaque, seen head-on (the headlight gives full light): every pixel of the sheet is the map's
  // colour of its value; with the range above every value, cool-warm's low end, Moreland's
  // (59, 76, 192).
  const fs::path file = write("sheet.vtp", sheet());
  const fs::path out = dir() / "low.png";
  const CliResult r =
      runCli("render " + file.string() +
             " --size 32x32 --opacity 1 -m abuffer-ll --color-by pressure --color-range 10,20 -o " + out.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const mfr::ImageRGBA8 low = mfr::readPng(out);
  for (const auto& [x, y] : {std::pair{16, 16}, {10, 20}, {22, 9}}) {
    EXPECT_EQ(low.at(x, y)[0], 59) << x << "," << y;
    EXPECT_EQ(low.at(x, y)[1], 76);
    EXPECT_EQ(low.at(x, y)[2], 192);
  }
}

TEST_F(CliColorBy, TheProbeGivesEachFragmentsValue) {
  // Opaque and head-on: the fragment's colour is exactly the map's colour of the value the probe
  // reports, and the value lies in the field's range.
  const fs::path file = write("sheet.vtp", sheet()), json = dir() / "probe.json";
  const CliResult r =
      runCli("probe " + file.string() +
             " --size 40x40 --pixel 13,22 --opacity 1 --color-by pressure --color-map rainbow --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("field value"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("pressure "), std::string::npos) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["fragments"].size(), 1u);
  const nlohmann::json& f = j["fragments"][0];
  EXPECT_EQ(f["field"], "pressure");
  const float value = f["field_value"].get<float>();
  EXPECT_GT(value, -2.0f);
  EXPECT_LT(value, 3.0f);
  const glm::vec3 expected = mfr::mapFieldValue(mfr::colorMap("rainbow"), value, {-2.0f, 3.0f});
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(f["rgba"][static_cast<std::size_t>(c)].get<double>(), std::round(expected[c] * 255.0f), 1.0) << c;
}

TEST_F(CliColorBy, SceneFileColorByEqualsTheOptions) {
  const fs::path file = write("sheet.vtp", sheet());
  const fs::path scene = write("s.mfrscene", R"({"objects": [{"file": "sheet.vtp", "opacity": 0.7,
         "color_by": {"field": "velocity:magnitude", "map": "magma", "range": [1, 2.5]}}]})");
  const fs::path fromFile = dir() / "f.png", fromOptions = dir() / "o.png";
  ASSERT_EQ(runCli("render " + scene.string() + " --size 48x48 -m abuffer-ll -o " + fromFile.string()).exitCode, 0);
  const CliResult r =
      runCli("render " + file.string() +
             " --size 48x48 --opacity 0.7 -m abuffer-ll --color-by velocity:magnitude --color-map magma "
             "--color-range 1,2.5 -o " +
             fromOptions.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(mfr::rmse(mfr::readPng(fromFile), mfr::readPng(fromOptions)), 0.0);
  // The stats say what the parts show, from the GPU renderer and the oracle alike.
  for (const std::string method : {"abuffer-ll", "oracle"}) {
    const fs::path stats = dir() / ("stats-" + method + ".json");
    ASSERT_EQ(runCli("render " + scene.string() + " --size 16x16 -m " + method + " -o " + (dir() / "s.png").string() +
                     " --stats " + stats.string())
                  .exitCode,
              0);
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["notes"]["field colours"], "velocity:magnitude (magma, 1 … 2.5) on 1 of 1 parts") << method;
  }
  // The scene file's short form: a field name alone (cool-warm over the data range).
  const fs::path shortForm = write("short.mfrscene", R"({"objects": [{"file": "sheet.vtp", "color_by": "pressure"}]})");
  const fs::path a = dir() / "a.png", b = dir() / "b.png";
  ASSERT_EQ(runCli("render " + shortForm.string() + " --size 32x32 -m abuffer-ll -o " + a.string()).exitCode, 0);
  ASSERT_EQ(
      runCli("render " + file.string() + " --size 32x32 -m abuffer-ll --color-by pressure -o " + b.string()).exitCode,
      0);
  EXPECT_EQ(mfr::rmse(mfr::readPng(a), mfr::readPng(b)), 0.0);
}

TEST_F(CliColorBy, BadFieldsMapsAndRangesAreOneLine) {
  const fs::path file = write("sheet.vtp", sheet());
  const std::string render = "render " + file.string() + " --size 16x16 ";
  expectCleanFailure(render + "--color-by nope",
                     "no point-data or cell-data array 'nope' (fields: pressure, velocity, "
                     "velocity:1, velocity:2, velocity:magnitude, zone)");
  expectCleanFailure(render + "--color-by velocity:3", "array 'velocity' has 3 components");
  expectCleanFailure(render + "--color-by pressure --color-map jet", "--color-map jet: unknown colour map");
  expectCleanFailure(render + "--color-by pressure --color-range 2,1", "--color-range 2,1: expected LO,HI");
  expectCleanFailure(render + "--color-by pressure --color-range 0,nan", "--color-range 0,nan");
  // Beyond single precision the renderers' map had an infinite span (the oracle indexed its table
  // with NaN and crashed, with --legend every method).
  for (const char* range : {"-1e308,1e308", "0,1e39", "1,1.00000001"})
    for (const char* method : {"oracle", "abuffer-ll"})
      expectCleanFailure("render " + file.string() + " --size 128x128 -m " + method +
                             " --color-by pressure --legend --color-range " + range,
                         "colour range must be two finite values, low < high, within single precision");
  expectCleanFailure(render + "--color-map viridis", "--color-map viridis: needs --color-by");
  expectCleanFailure("render @sample --size 16x16 --color-by pressure", "(it has none)");
  const fs::path bad = write("bad.mfrscene", R"({"objects": [{"file": "sheet.vtp", "color_by": {"field": "nope"}}]})");
  expectCleanFailure("render " + bad.string() + " --size 16x16", "objects[0].color_by: sheet.vtp: no point-data");
  const fs::path badMap =
      write("map.mfrscene", R"({"objects": [{"file": "sheet.vtp", "color_by": {"field": "zone", "map": "jet"}}]})");
  expectCleanFailure("render " + badMap.string() + " --size 16x16", "objects[0].color_by.map: unknown colour map");
  // "@NAME" names a volume, and a volume alone has no surface: both were blamed on an array.
  expectCleanFailure("render @volume --size 16x16 --color-by @x",
                     "--color-by @x: volume: no volume 'x' to sample (volumes: @field)");
  expectCleanFailure("render @sample --size 16x16 --color-by @x",
                     "--color-by @x: sample: no volume 'x' to sample (the scene has none)");
  const fs::path grid = write("grid.vtk",
                              "# vtk DataFile Version 3.0\ngrid\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n"
                              "ORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 8\nSCALARS v float 1\n"
                              "LOOKUP_TABLE default\n0 1 0 1 0 1 0 1\n");
  expectCleanFailure("render " + grid.string() + " --size 16x16 --color-by @v",
                     "--color-by @v: grid.vtk: no surfaces to colour (--contour adds isosurfaces of a volume)");
  // Nor any for --opacity, which was taken and changed nothing (a bug hunt); with --contour it has.
  expectCleanFailure("render " + grid.string() + " --size 16x16 --opacity 0.5",
                     "--opacity: scene 'grid.vtk' has no surfaces (a volume's opacity is its transfer function's; "
                     "--contour adds isosurfaces)");
  EXPECT_EQ(
      runCli("render " + grid.string() + " --size 16x16 --opacity 0.5 --contour 0.5 -o " + (dir() / "c.png").string())
          .exitCode,
      0);
  // One file listed twice without names: "@grid.vtk" could mean either volume, and meant the first
  // without a word (a bug hunt); named, each is its own field.
  const std::string twice =
      R"({"volumes": [{"file": "grid.vtk"}, {"file": "grid.vtk", "transform": {"translate": [5, 0, 0]}}],
      "objects": [{"primitive": {"type": "sphere", "radius": 0.3}, "transform": {"translate": [5.5, 0.5, 0.5]})";
  const fs::path ambiguous = write("twice.mfrscene", twice + R"(, "color_by": "@grid.vtk"}]})");
  expectCleanFailure("render " + ambiguous.string() + " --size 16x16",
                     "objects[0].color_by: '@grid.vtk' is the field of 2 volumes (give them names");
  const fs::path uncoloured = write("plain.mfrscene", twice + "}]}");
  expectCleanFailure("render " + uncoloured.string() + " --size 16x16 --color-by @grid.vtk",
                     "--color-by @grid.vtk: '@grid.vtk' is the field of 2 volumes");
  const fs::path named = write("named.mfrscene", R"({"volumes": [{"file": "grid.vtk", "name": "a"},
      {"file": "grid.vtk", "name": "b", "transform": {"translate": [5, 0, 0]}}],
      "objects": [{"primitive": {"type": "sphere", "radius": 0.3}, "transform": {"translate": [5.5, 0.5, 0.5]},
      "color_by": "@b"}]})");
  const CliResult ok = runCli("render " + named.string() + " --size 16x16 -o " + (dir() / "n.png").string());
  EXPECT_EQ(ok.exitCode, 0) << ok.out;
}

}  // namespace
