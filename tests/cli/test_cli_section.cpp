// --section end to end: the GPU image equals the oracle's under the same plane, the plane and its
// caps change the image, the axis form equals the point-normal form, a scene file's "section" is
// honoured and "none" removes it, open parts are named in a note, and bad planes are one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"
#include "mfr/reference/metrics.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

using CliSection = mfr::test::CliTest;

TEST_F(CliSection, GpuEqualsOracleAndThePlaneCuts) {
  const fs::path oracle = dir() / "o.png", gpu = dir() / "g.png", whole = dir() / "w.png", open = dir() / "n.png",
                 pointNormal = dir() / "p.png";
  const std::string common = "render @sample --size 64x48 --view iso ";
  ASSERT_EQ(runCli(common + "--section -x=0.1 -o " + oracle.string()).exitCode, 0);
  const CliResult r = runCli(common + "--section -x=0.1 -m abuffer-ll -o " + gpu.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  ASSERT_EQ(runCli(common + "-m abuffer-ll -o " + whole.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + "--section -x=0.1:nocaps -m abuffer-ll -o " + open.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + "--section 0.1,7,-3,-2,0,0 -m abuffer-ll -o " + pointNormal.string()).exitCode, 0);
  const mfr::ImageRGBA8 o = mfr::readPng(oracle), g = mfr::readPng(gpu), w = mfr::readPng(whole);
  EXPECT_LT(mfr::rmse(o, g), 0.02);                         // edge pixels may differ; everything else is exact
  EXPECT_GT(mfr::rmse(w, g), 0.05);                         // the plane removes much of the sample
  EXPECT_GT(mfr::rmse(mfr::readPng(open), g), 0.005);       // caps are drawn
  EXPECT_EQ(mfr::rmse(mfr::readPng(pointNormal), g), 0.0);  // x <= 0.1 either way
  // Right of x = 0.1 nothing is drawn: the right columns are background.
  EXPECT_EQ(g.at(61, 24)[0], 255);
  EXPECT_EQ(g.at(61, 24)[1], 255);
}

TEST_F(CliSection, SceneFileSectionNoneAndOpenParts) {
  const fs::path scene =
      write("s.mfrscene", R"({"sample": true, "section": {"point": [0.1, 0, 0], "normal": [-1, 0, 0]}})");
  const fs::path fromFile = dir() / "f.png", fromOption = dir() / "o.png", none = dir() / "n.png",
                 plain = dir() / "p.png";
  ASSERT_EQ(runCli("render " + scene.string() + " --size 48x40 -m abuffer-ll -o " + fromFile.string()).exitCode, 0);
  ASSERT_EQ(runCli("render @sample --size 48x40 -m abuffer-ll --section -x=0.1 -o " + fromOption.string()).exitCode, 0);
  ASSERT_EQ(
      runCli("render " + scene.string() + " --size 48x40 -m abuffer-ll --section none -o " + none.string()).exitCode,
      0);
  ASSERT_EQ(runCli("render @sample --size 48x40 -m abuffer-ll -o " + plain.string()).exitCode, 0);
  EXPECT_EQ(mfr::rmse(mfr::readPng(fromFile), mfr::readPng(fromOption)), 0.0);
  EXPECT_EQ(mfr::rmse(mfr::readPng(none), mfr::readPng(plain)), 0.0);
  EXPECT_GT(mfr::rmse(mfr::readPng(fromFile), mfr::readPng(plain)), 0.05);
  // A one-sided plane is not a solid: cut, not capped, and named.
  const fs::path sheet = write("sheet.mfrscene", R"({"objects": [{"name": "sheet", "primitive": {"type": "plane"}},
      {"name": "block", "primitive": {"type": "box"}}]})");
  const CliResult r =
      runCli("render " + sheet.string() + " --size 32x32 --section x=0 -o " + (dir() / "s.png").string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("note: section: 1 of 2 cut parts have no cap (not closed surfaces): sheet"), std::string::npos)
      << r.out;
}

// The CSG sample cut obliquely: the cut solids stay closed, so CSG runs on them, on the GPU as in
// the oracle, and the cut shows.
TEST_F(CliSection, CsgRunsOnCutSolids) {
  const fs::path oracle = dir() / "o.png", gpu = dir() / "g.png", whole = dir() / "w.png";
  const std::string common = "render @csg --op csg --size 64x48 --view iso ";
  const std::string plane = "--section 0,0,0,0.3,-1,0.6 ";
  const CliResult r = runCli(common + plane + "-m abuffer-ll -o " + gpu.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;  // every part capped
  ASSERT_EQ(runCli(common + plane + "-o " + oracle.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + "-m abuffer-ll -o " + whole.string()).exitCode, 0);
  const mfr::ImageRGBA8 o = mfr::readPng(oracle), g = mfr::readPng(gpu), w = mfr::readPng(whole);
  EXPECT_LT(mfr::rmse(o, g), 0.03);
  EXPECT_GT(mfr::rmse(w, g), 0.05);
}

// :slice adds each volume's slice: the GPU draws it as the oracle does, it changes the picture,
// and :nocaps:slice is accepted too.
TEST_F(CliSection, VolumeSliceOnGpuEqualsTheOracle) {
  const fs::path oracle = dir() / "o.png", gpu = dir() / "g.png", plain = dir() / "p.png";
  const std::string common = "render @volume --size 64x48 --view iso --section -z=0.1";
  ASSERT_EQ(runCli(common + ":slice -m oracle -o " + oracle.string()).exitCode, 0);
  const CliResult g = runCli(common + ":slice -m abuffer-ll -o " + gpu.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  ASSERT_EQ(runCli(common + " -m abuffer-ll -o " + plain.string()).exitCode, 0);
  EXPECT_EQ(runCli(common + ":nocaps:slice -m abuffer-ll -o " + plain.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + " -m abuffer-ll -o " + plain.string()).exitCode, 0);
  const mfr::ImageRGBA8 o = mfr::readPng(oracle.string()), s = mfr::readPng(gpu.string()),
                        p = mfr::readPng(plain.string());
  EXPECT_LT(mfr::rmse(o, s), 0.02);
  EXPECT_GT(mfr::rmse(p, s), 0.05);
  const CliResult miss = runCli("render @volume --size 16x16 --section -z=5:slice -m abuffer-ll -o " + plain.string());
  EXPECT_NE(miss.out.find("misses every volume's box"), std::string::npos) << miss.out;
}

// A section leaves the scene's extent alone: the default z-thickness (1 % of the diagonal) and the
// fit view are the whole scene's (the cut meshes gave 0.0404 instead of 0.0448 on @intersect, and
// framed the kept part).
// mfr info on a section with a slice read the section's per-part report past its end for the
// slice part (a segfault, or garbage under gdb; a bug hunt): the slice is a kept part of its own.
TEST_F(CliSection, InfoMeasuresTheSlice) {
  // A box and a volume of [-1, 1]^3 (this crashed every time).
  write("g.vtk",
        "# vtk DataFile Version 3.0\ngrid\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nORIGIN -1 -1 -1\n"
        "SPACING 2 2 2\nPOINT_DATA 8\nSCALARS v float 1\nLOOKUP_TABLE default\n0 1 0 1 0 1 0 1\n");
  const fs::path scene = write(
      "s.mfrscene", R"({"objects": [{"name": "b", "primitive": {"type": "box"}}], "volumes": [{"file": "g.vtk"}]})");
  const fs::path json = dir() / "info.json";
  const CliResult r = runCli("info " + scene.string() + " --section z=0:slice --no-histogram --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(json));
  ASSERT_EQ(j["part_list"].size(), 2u);
  const nlohmann::json& slice = j["part_list"][1];
  EXPECT_EQ(slice["name"], "g.vtk slice");
  EXPECT_EQ(slice["section"], "kept");
  EXPECT_EQ(slice["cross_section_area"], 0.0);
  EXPECT_NEAR(slice["area"].get<double>(), 4.0, 1e-9);  // the volume box's 2 x 2 face at z = 0
  EXPECT_EQ(j["part_list"][0]["section"], "capped");
}

TEST_F(CliSection, TheCutKeepsTheScenesExtent) {
  const auto thickness = [&](const std::string& extra) {
    const fs::path stats = dir() / "stats.json";
    const CliResult r = runCli("render @intersect --op zthickness -m abuffer-ll -s 32x32 -o " +
                               (dir() / "t.png").string() + " --stats " + stats.string() + extra);
    EXPECT_EQ(r.exitCode, 0) << r.out;
    std::ifstream in(stats);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find("\"z-thickness\": \"");
    return at == std::string::npos ? std::string("missing") : text.substr(at + 16, 8);
  };
  EXPECT_EQ(thickness(" --section z=0.3"), thickness(""));
  EXPECT_EQ(thickness(""), "0.044802");  // 1 % of the scene's diagonal, as printed before the fix
}

TEST_F(CliSection, BadPlanesAreRefused) {
  expectCleanFailure("render @sample --size 16x16 --section 1,2,3",
                     "--section 1,2,3: expected AXIS=VALUE or six numbers");
  expectCleanFailure("render @sample --size 16x16 --section w=1", "expected AXIS=VALUE with AXIS one of");
  expectCleanFailure("render @sample --size 16x16 --section x=nan", "expected AXIS=VALUE");
  expectCleanFailure("render @sample --size 16x16 --section 0,0,0,0,0,0", "the normal must not be zero");
  expectCleanFailure("render @sample --size 16x16 --section x=0:caps", "the suffixes are :nocaps and :slice");
  // A stray ':' was read past.
  expectCleanFailure("render @sample --size 16x16 --section x=0:", "(nothing after ':')");
  expectCleanFailure("render @sample --size 16x16 --section x=0:nocaps:", "the suffixes are :nocaps and :slice");
  expectCleanFailure("render @volume --size 16x16 --section x=0:slice:slice",
                     "--section x=0:slice:slice: :slice is given twice");
  expectCleanFailure("render @sample --size 16x16 --section 0,0,0,,1,0,0", "expected AXIS=VALUE or six numbers");
  expectCleanFailure("render @sample --size 16x16 --section x=0:slice",
                     "--section x=0:slice: slice: scene 'sample' has no volume");
  // The argument or the scene file that gave the plane is named (they read "section plane: …" or
  // "section: slice: …", naming neither; a bug hunt).
  expectCleanFailure("render @sample --size 16x16 --section x=100",
                     "mfr: --section x=100: cuts away every visible surface of scene 'sample'");
  const std::string away =
      write("away.mfrscene",
            R"({"sample": true, "name": "study", "section": {"point": [0, 0, 5], "normal": [0, 0, 1]}})")
          .string();
  expectCleanFailure("render " + away + " --size 16x16",
                     "mfr: " + away + ": section: cuts away every visible surface of scene 'study'");
  const std::string slice =
      write("slice.mfrscene",
            R"({"sample": true, "name": "study", "section": {"point": [0, 0, 0], "normal": [0, 0, 1], "slice": true}})")
          .string();
  expectCleanFailure("render " + slice + " --size 16x16",
                     "mfr: " + slice + ": section: slice: scene 'study' has no volume");
  // CSG on solids a section without caps cut open: the message said only "object 'a': not a
  // closed surface", as if the file were at fault (a bug hunt).
  expectCleanFailure("render @csg --size 16x16 --section x=0:nocaps --op csg",
                     "the section without caps cut it open: CSG needs the caps");
}

}  // namespace
