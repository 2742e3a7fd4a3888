// mfr render --op zthickness end to end: the oracle and an A-buffer agree on the built-in
// intersecting-surfaces sample, --thickness reaches the image and the stats, mfr bench measures
// zthickness rows against the oracle's zthickness image, and bad input fails with one line.
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

using CliZThickness = mfr::test::CliTest;

TEST_F(CliZThickness, OracleAndGpuAgreeAndTheThicknessMatters) {
  const std::string common = "render @intersect --view iso --size 96x80 --op zthickness";
  const fs::path oracle = dir() / "oracle.png", gpu = dir() / "gpu.png", thick = dir() / "thick.png",
                 over = dir() / "over.png", stats = dir() / "stats.json";
  ASSERT_EQ(runCli(common + " -o " + oracle.string()).exitCode, 0);
  const CliResult g = runCli(common + " -m abuffer-ll -o " + gpu.string() + " --stats " + stats.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  EXPECT_LT(rmseOf(oracle, gpu), 0.01);  // edge pixels only
  ASSERT_EQ(runCli(common + " -m abuffer-ll --thickness 0.3 -o " + thick.string()).exitCode, 0);
  ASSERT_EQ(runCli("render @intersect --view iso --size 96x80 -m abuffer-ll -o " + over.string()).exitCode, 0);
  EXPECT_GT(rmseOf(gpu, thick), 0.01);
  EXPECT_GT(rmseOf(gpu, over), 0.005);  // the crossing spheres and the doubled plate
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["operation"], "zthickness");
  // Default thickness: 1 % of the diagonal of @intersect's bounds, by hand from its parts: x from
  // the plate's -1.4 to the ring's 1.43, y from the ring's -1.78 to the scan's 1.06, z ±1.0 → 4.5.
  EXPECT_NEAR(std::stod(j["notes"]["z-thickness"].get<std::string>()), 0.045, 0.001) << j.dump();
}

TEST_F(CliZThickness, BenchMeasuresRowsAgainstTheOraclesZThickness) {
  const fs::path json = dir() / "bench.json";
  const CliResult r = runCli(
      "bench @intersect --view iso --size 96x80 -r 1 -m "
      "abuffer-ll,abuffer-ll:op=zthickness:thickness=0.2,kbuffer-zmerge:k=32 --json " +
      json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["results"].size(), 3u);
  EXPECT_EQ(j["results"][1]["method"], "abuffer-ll:op=zthickness:thickness=0.2");
  EXPECT_LT(j["results"][1]["rmse"].get<double>(), 0.01);  // against "over" it would be far larger
  EXPECT_EQ(j["results"][1]["notes"]["z-thickness"], "0.2");
  // A method whose own operation is zthickness ("auto") is measured against that image too.
  EXPECT_LT(j["results"][2]["rmse"].get<double>(), 0.005);
}

TEST_F(CliZThickness, BadInputIsOneLine) {
  expectCleanFailure("render @intersect --op zthickness --thickness -1", "--thickness");
  expectCleanFailure("render @intersect --op zthickness --thickness 0", "--thickness");
  expectCleanFailure("render @intersect --op zthickness --thickness nan", "--thickness");
  expectCleanFailure("render @intersect --op zthickness --method peel-f2b", "peel-f2b");
  expectCleanFailure("render @intersect --op zthickness --method wboit", "wboit");
  expectCleanFailure("render @intersect --op zthickness --method optimal-k", "optimal-k");
  expectCleanFailure("render @intersect --op thick", "zthickness");  // the list of operations
  expectCleanFailure("render @intersect --op oit --method kbuffer-zmerge", "zthickness only");
  expectCleanFailure("render @intersect --method kbuffer-zmerge -p k=33", "k");
  const fs::path json = dir() / "b.json";
  const CliResult bench = runCli("bench @intersect -m abuffer-ll:op=zthickness:thickness=-2 --json " + json.string());
  EXPECT_NE(bench.exitCode, 0);
  EXPECT_EQ(std::count(bench.out.begin(), bench.out.end(), '\n'), 1) << bench.out;
  EXPECT_NE(bench.out.find("thickness"), std::string::npos) << bench.out;
  EXPECT_FALSE(fs::exists(json));
}

}  // namespace
