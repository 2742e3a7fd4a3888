// --clip end to end: the GPU image equals the oracle's under the same box, the box changes the
// image, a scene file's "clip" is honoured and "none" removes it, CSG refuses a box, and bad boxes
// are one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mfr/image.hpp"
#include "mfr/reference/metrics.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

using CliClip = mfr::test::CliTest;

// The sample's world bounds are about ±1.1; this box keeps its right half, front part.
constexpr const char* kBox = "0,-2,-2,2,2,0.3";

TEST_F(CliClip, GpuEqualsOracleAndTheBoxCuts) {
  const fs::path oracle = dir() / "o.png", gpu = dir() / "g.png", whole = dir() / "w.png";
  const std::string common = "render @sample --size 64x48 --view iso ";
  ASSERT_EQ(runCli(common + "--clip " + kBox + " -o " + oracle.string()).exitCode, 0);
  const CliResult r = runCli(common + "--clip " + kBox + " -m abuffer-ll -o " + gpu.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  ASSERT_EQ(runCli(common + "-m abuffer-ll -o " + whole.string()).exitCode, 0);
  const mfr::ImageRGBA8 o = mfr::readPng(oracle), g = mfr::readPng(gpu), w = mfr::readPng(whole);
  EXPECT_LT(mfr::rmse(o, g), 0.02);  // edge pixels may differ; everything else is exact
  EXPECT_GT(mfr::rmse(w, g), 0.05);  // the box removes much of the sample
  // Left of x = 0 nothing is drawn: the left columns are background.
  EXPECT_EQ(g.at(2, 24)[0], 255);
  EXPECT_EQ(g.at(2, 24)[1], 255);
}

TEST_F(CliClip, SceneFileClipAndNone) {
  const fs::path scene = write("s.mfrscene", R"({"sample": true, "clip": {"min": [0, -2, -2], "max": [2, 2, 0.3]}})");
  const fs::path fromFile = dir() / "f.png", fromOption = dir() / "o.png", none = dir() / "n.png",
                 plain = dir() / "p.png";
  ASSERT_EQ(runCli("render " + scene.string() + " --size 48x40 -m abuffer-ll -o " + fromFile.string()).exitCode, 0);
  ASSERT_EQ(
      runCli(std::string("render @sample --size 48x40 -m abuffer-ll --clip ") + kBox + " -o " + fromOption.string())
          .exitCode,
      0);
  ASSERT_EQ(runCli("render " + scene.string() + " --size 48x40 -m abuffer-ll --clip none -o " + none.string()).exitCode,
            0);
  ASSERT_EQ(runCli("render @sample --size 48x40 -m abuffer-ll -o " + plain.string()).exitCode, 0);
  EXPECT_EQ(mfr::rmse(mfr::readPng(fromFile), mfr::readPng(fromOption)), 0.0);
  EXPECT_EQ(mfr::rmse(mfr::readPng(none), mfr::readPng(plain)), 0.0);
  EXPECT_GT(mfr::rmse(mfr::readPng(fromFile), mfr::readPng(plain)), 0.05);
}

TEST_F(CliClip, BadBoxesAndCsgAreRefused) {
  expectCleanFailure("render @sample --size 16x16 --clip 1,2,3", "--clip 1,2,3: expected six numbers");
  expectCleanFailure("render @sample --size 16x16 --clip 0,0,0,1,x,1", "expected six numbers");
  expectCleanFailure("render @sample --size 16x16 --clip 0,2,0,1,1,1", "min must not exceed max");
  expectCleanFailure("render @sample --size 16x16 --clip 0,0,0,1,1,inf", "expected six numbers");
  // A box that holds nothing drew an empty image (found by fuzzing); a section plane that leaves
  // nothing is refused too.
  expectCleanFailure("render @sample --size 16x16 --clip 100,100,100,101,101,101", "holds nothing of scene 'sample'");
  expectCleanFailure("render @sample --size 16x16 -m abuffer-ll --clip 0,0,0,0,0,0", "holds nothing of scene 'sample'");
  // Beyond a float's range the GPU's box held nothing and the oracle's everything (a bug hunt).
  expectCleanFailure("render @sample --size 16x16 -m abuffer-ll --clip=-1e39,-1,-1,1,1,1",
                     "--clip -1e39,-1,-1,1,1,1: a corner lies beyond a float's range (±3.4e38)");
  expectCleanFailure("render @csg --size 16x16 --op csg -m abuffer-ll --clip -1,-1,-1,1,1,1", "clip box");
  expectCleanFailure("render @csg --size 16x16 --op csg --clip -1,-1,-1,1,1,1", "clip box");
}

}  // namespace
