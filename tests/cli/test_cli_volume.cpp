// mfr render --op volume end to end: the oracle and the GPU agree on the built-in volume sample,
// "auto" picks the volume for a scene that has one, --step reaches the image and the stats, mfr
// bench measures volume rows against the oracle's volume image, and bad input fails with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::CliResult;
using mfr::test::runCli;

using CliVolume = mfr::test::CliTest;

TEST_F(CliVolume, OracleAndGpuAgreeAndTheStepMatters) {
  const std::string common = "render @volume --view iso --size 96x80";
  const fs::path oracle = dir() / "oracle.png", gpu = dir() / "gpu.png", coarse = dir() / "coarse.png",
                 over = dir() / "over.png", stats = dir() / "stats.json";
  ASSERT_EQ(runCli(common + " -o " + oracle.string()).exitCode, 0);  // auto: volume
  const CliResult g =
      runCli(common + " -m abuffer-sbuffer --op volume -o " + gpu.string() + " --stats " + stats.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  EXPECT_LT(rmseOf(oracle, gpu), 0.01);  // edge pixels only
  ASSERT_EQ(runCli(common + " -m abuffer-sbuffer --step 0.4 -o " + coarse.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + " -m abuffer-sbuffer --op oit -o " + over.string()).exitCode, 0);
  EXPECT_GT(rmseOf(gpu, coarse), 0.003);
  EXPECT_GT(rmseOf(gpu, over), 0.02);  // the medium
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["operation"], "volume");
  // Default step: half the sample's grid spacing, 2/95 / 2.
  EXPECT_NEAR(std::stod(j["notes"]["volume step"].get<std::string>()), 1.0 / 95.0, 1e-5) << j.dump();
  EXPECT_EQ(j["notes"]["volume (bytes)"], std::to_string(96 * 96 * 96 * 4 + 256 * 16));
}

// A ray marches at most 4096 steps: with a step so fine that the longest ray through the volume
// (@volume: [-1, 1]³, diagonal 2√3) would need more, the stats say how long its step gets; the
// "volume step" note alone stated the step asked for. At the default step no ray is that long.
TEST_F(CliVolume, StatsSayWhenLongRaysTakeALongerStep) {
  const fs::path stats = dir() / "stats.json", out = dir() / "out.png";
  const auto notes = [&](const std::string& args) {
    const CliResult r =
        runCli("render @volume --view iso --size 24x20 " + args + " -o " + out.string() + " --stats " + stats.string());
    EXPECT_EQ(r.exitCode, 0) << r.out;
    std::ifstream in(stats);
    return nlohmann::json::parse(in)["notes"];
  };
  for (const std::string method : {"oracle", "abuffer-sbuffer"}) {
    const nlohmann::json fine = notes("-m " + method + " --step 0.0001");
    EXPECT_EQ(fine["volume step"], "1e-04") << method;
    const std::string longRays = fine.value("volume step, long rays", "");
    ASSERT_EQ(longRays.rfind("up to ", 0), 0u) << method << ": " << fine.dump();
    EXPECT_NEAR(std::stod(longRays.substr(6)), 2.0 * std::sqrt(3.0) / 4096.0, 1e-12) << longRays;
    EXPECT_NE(longRays.find("a ray longer than 4096 steps takes its length / 4096"), std::string::npos);
    EXPECT_FALSE(notes("-m " + method).contains("volume step, long rays")) << method;
  }
}

TEST_F(CliVolume, ShadeTurnsOnGradientShading) {
  const std::string common = "render @volume --view iso --size 96x80";
  const fs::path plain = dir() / "plain.png", oracle = dir() / "oracle.png", gpu = dir() / "gpu.png",
                 stats = dir() / "stats.json";
  ASSERT_EQ(runCli(common + " -m abuffer-sbuffer -o " + plain.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + " --shade -o " + oracle.string()).exitCode, 0);
  const CliResult g = runCli(common + " --shade -m abuffer-sbuffer -o " + gpu.string() + " --stats " + stats.string());
  ASSERT_EQ(g.exitCode, 0) << g.out;
  EXPECT_LT(rmseOf(oracle, gpu), 0.01);  // edge pixels only
  EXPECT_GT(rmseOf(plain, gpu), 0.01);   // the medium is lit differently
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["notes"]["volume shading"], "on") << j.dump();
}

TEST_F(CliVolume, BenchMeasuresRowsAgainstTheOraclesVolumeImage) {
  const fs::path json = dir() / "bench.json";
  const CliResult r = runCli(
      "bench @volume --view iso --size 96x80 -r 1 -m abuffer-ll,abuffer-ll:op=oit,kplus-array:k=64:step=0.05 --json " +
      json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["results"].size(), 3u);
  EXPECT_LT(j["results"][0]["rmse"].get<double>(), 0.01);
  // op=oit leaves the volume out and is measured against "over": also close, but a different image.
  EXPECT_EQ(j["results"][1]["notes"]["volume"], "not drawn (operation oit)");
  EXPECT_LT(j["results"][1]["rmse"].get<double>(), 0.01);
  EXPECT_EQ(j["results"][2]["method"], "kplus-array:k=64:step=0.05");
  EXPECT_EQ(j["results"][2]["notes"]["volume step"], "0.05");
  EXPECT_LT(j["results"][2]["rmse"].get<double>(), 0.01);
}

// Every renderer that leaves a scene's volume out says so; optimal-k (hybrid, surfaces only) did not.
TEST_F(CliVolume, ARenderWithoutTheVolumeSaysSo) {
  for (const std::string method : {"oracle --op oit", "abuffer-ll --op oit", "optimal-k"}) {
    SCOPED_TRACE(method);
    const fs::path png = dir() / "out.png", stats = dir() / "stats.json";
    const CliResult r =
        runCli("render @volume -s 24x24 -m " + method + " -o " + png.string() + " --stats " + stats.string());
    ASSERT_EQ(r.exitCode, 0) << r.out;
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["notes"]["volume"], "not drawn (operation " + j["operation"].get<std::string>() + ")") << j.dump();
  }
}

TEST_F(CliVolume, InfoDescribesTheVolume) {
  const fs::path json = dir() / "info.json";
  const CliResult r = runCli("info @volume --no-histogram --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("volume: field (96x96x96 points"), std::string::npos) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["volumes"].size(), 1u);
  EXPECT_EQ(j["volumes"][0]["dims"], nlohmann::json({96, 96, 96}));
  EXPECT_NEAR(j["volumes"][0]["bounds"]["max"][0].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(j["volumes"][0]["range"][1].get<double>(), 1.0, 0.01);  // the core's peak (blobs add a little)
}

TEST_F(CliVolume, BadInputIsOneLine) {
  expectCleanFailure("render @volume --step -1", "--step");
  expectCleanFailure("render @volume --step 0", "--step");
  expectCleanFailure("render @volume --step nan", "--step");
  expectCleanFailure("render @volume --op volume --method peel-dual", "peel-dual");
  expectCleanFailure("render @volume --op volume --method mboit", "mboit");
  expectCleanFailure("render @sample --op volume", "no visible volume");
  expectCleanFailure("render @sample --op volume --method abuffer-ll", "no visible volume");
  expectCleanFailure("render @sample --shade", "--shade");
  expectCleanFailure("render @sample --step 0.1", "--step: scene 'sample' has no volume");  // was ignored
  const fs::path json = dir() / "b.json";
  const CliResult bench = runCli("bench @volume -m abuffer-ll:step=-3 --json " + json.string());
  EXPECT_NE(bench.exitCode, 0);
  EXPECT_EQ(std::count(bench.out.begin(), bench.out.end(), '\n'), 1) << bench.out;
  EXPECT_NE(bench.out.find("step"), std::string::npos) << bench.out;
  EXPECT_FALSE(fs::exists(json));
  // A file's own origin far beyond what can be drawn (found by a bug hunt: it rendered blank).
  const fs::path far = write("far.vtk",
                             "# vtk DataFile Version 3.0\nfar\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n"
                             "ORIGIN 1e300 0 0\nSPACING 1 1 1\nPOINT_DATA 8\nSCALARS v float 1\n"
                             "LOOKUP_TABLE default\n0 1 0 1 0 1 0 1\n");
  expectCleanFailure("render " + far.string(), "far.vtk: volume 'far.vtk': reaches beyond ±1e15");
}

// A legacy VTK structured-points file: the box [-1, 1]³ on a 5³ grid, every value 0.5.
void writeUniformVolume(const fs::path& path) {
  std::ofstream out(path);
  out << "# vtk DataFile Version 3.0\nuniform\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 5 5 5\n"
         "ORIGIN -1 -1 -1\nSPACING 0.5 0.5 0.5\nPOINT_DATA 125\nSCALARS v float 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < 125; ++i) out << "0.5\n";
}

// A legacy VTK file with two arrays over [-1, 1]³ on a 5³ grid: "ramp" rising along x, "dip" falling.
void writeTwoArrayVolume(const fs::path& path) {
  std::ofstream out(path);
  out << "# vtk DataFile Version 3.0\ntwo arrays\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 5 5 5\n"
         "ORIGIN -1 -1 -1\nSPACING 0.5 0.5 0.5\nPOINT_DATA 125\nSCALARS ramp float 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < 125; ++i) out << i % 5 << "\n";
  out << "SCALARS dip float 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < 125; ++i) out << 10 - i % 5 << "\n";
}

// --field reads another array: info names the one read and lists the others, the image changes,
// the default is the first array; an array the file lacks or --field on a model is one line.
TEST_F(CliVolume, FieldChoosesTheArray) {
  const fs::path vtk = dir() / "two.vtk", json = dir() / "info.json";
  writeTwoArrayVolume(vtk);
  const CliResult info = runCli("info " + vtk.string() + " --field dip --no-histogram --json " + json.string());
  ASSERT_EQ(info.exitCode, 0) << info.out;
  EXPECT_NE(info.out.find("volume: two.vtk [dip] (5x5x5 points"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("values 6 … 10"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("fields: ramp dip (read)"), std::string::npos) << info.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["volumes"][0]["field"], "dip");
  EXPECT_EQ(j["volumes"][0]["fields"], nlohmann::json({"ramp", "dip"}));

  const std::string common = "render " + vtk.string() + " --size 64x48 -o ";
  const fs::path byDefault = dir() / "default.png", ramp = dir() / "ramp.png", dip = dir() / "dip.png",
                 dipGpu = dir() / "dip-gpu.png";
  ASSERT_EQ(runCli(common + byDefault.string()).exitCode, 0);
  ASSERT_EQ(runCli(common + ramp.string() + " --field ramp").exitCode, 0);
  ASSERT_EQ(runCli(common + dip.string() + " --field dip").exitCode, 0);
  const fs::path stats = dir() / "stats.json", oracleStats = dir() / "oracle-stats.json";
  ASSERT_EQ(runCli(common + dipGpu.string() + " --field dip -m abuffer-ll --stats " + stats.string()).exitCode, 0);
  // The stats say which field was drawn (GPU and oracle alike).
  ASSERT_EQ(runCli(common + dir().string() + "/o.png --field dip --stats " + oracleStats.string()).exitCode, 0);
  for (const fs::path& file : {stats, oracleStats}) {
    std::ifstream statsIn(file);
    const nlohmann::json s = nlohmann::json::parse(statsIn);
    EXPECT_EQ(s["notes"]["volume fields"], "dip") << file;
  }
  EXPECT_EQ(rmseOf(byDefault, ramp), 0.0);
  EXPECT_GT(rmseOf(ramp, dip), 0.02);
  EXPECT_LT(rmseOf(dip, dipGpu), 0.01);

  expectCleanFailure("render " + vtk.string() + " --field Dip",
                     "no point-data or cell-data array 'Dip' (arrays: ramp, dip)");
  expectCleanFailure("render " + vtk.string() + " --field Dip", vtk.string());
  expectCleanFailure("render @sample --field dip", "can be chosen only for a volume file");
}

// Two homogeneous volumes overlapping on x ∈ [0, 1] (red: opacity 0.5 per unit, blue: 0.3, moved
// +1 along x), seen along −z: where both lie the medium is their mixture — extinction σ_r + σ_b,
// colour weighted by σ — against the closed form; the probe splits the medium's share by volume;
// render and probe agree; a fifth visible volume is refused with one line.
TEST_F(CliVolume, TwoVolumesMixWhereTheyOverlap) {
  writeUniformVolume(dir() / "uniform.vtk");
  const std::string volumes =
      R"({"name": "red", "file": "uniform.vtk", "transfer": {"points": [[0, 1, 0, 0, 0.5], [1, 1, 0, 0, 0.5]], "unit_distance": 1}},
         {"name": "blue", "file": "uniform.vtk", "transform": {"translate": [1, 0, 0]},
          "transfer": {"points": [[0, 0, 0, 1, 0.3], [1, 0, 0, 1, 0.3]], "unit_distance": 1}})";
  const std::string views =
      R"("views": [{"name": "front", "eye": [0.5, 0, 5], "target": [0.5, 0, 0], "projection": "orthographic",
                    "height": 3}])";
  std::ofstream(dir() / "two.mfrscene") << R"({"background": [0, 0, 0], "volumes": [)" << volumes << "], " << views
                                        << "}";
  const std::string scene = (dir() / "two.mfrscene").string() + " --view front --size 64x64";
  const double sr = -std::log(0.5), sb = -std::log(0.7), chord = 2.0;
  // Pixel 32: x ≈ 0.52, inside both boxes; pixel 10: x ≈ -0.5, red only.
  const fs::path json = dir() / "probe.json";
  ASSERT_EQ(runCli("probe " + scene + " --pixel 32,32 --json " + json.string()).exitCode, 0);
  const nlohmann::json j = [&] {
    std::ifstream in(json);
    return nlohmann::json::parse(in);
  }();
  ASSERT_EQ(j["volumes"], nlohmann::json({"red", "blue"}));
  const double absorbed = 1.0 - std::exp(-(sr + sb) * chord);
  EXPECT_NEAR(j["volume_rgb"][0].get<int>(), std::lround(255.0 * sr / (sr + sb) * absorbed), 1);
  EXPECT_EQ(j["volume_rgb"][1].get<int>(), 0);
  EXPECT_NEAR(j["volume_rgb"][2].get<int>(), std::lround(255.0 * sb / (sr + sb) * absorbed), 1);
  double red = 0.0, blue = 0.0;
  for (const nlohmann::json& m : j["medium"]) {
    red += m["weight_by_volume"]["red"].get<double>();
    blue += m["weight_by_volume"]["blue"].get<double>();
  }
  EXPECT_NEAR(red, sr / (sr + sb) * absorbed, 1e-4);
  EXPECT_NEAR(blue, sb / (sr + sb) * absorbed, 1e-4);
  const CliResult text = runCli("probe " + scene + " --pixel 10,32");
  ASSERT_EQ(text.exitCode, 0) << text.out;
  EXPECT_NE(text.out.find("(medium) red"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("(medium) blue"), std::string::npos) << text.out;       // no blue medium there
  EXPECT_NE(text.out.find("red 75 %, blue 0 %"), std::string::npos) << text.out;  // 1 - 0.5²

  // The GPU draws the same mixture.
  const fs::path gpu = dir() / "gpu.png", oracle = dir() / "oracle.png", stats = dir() / "stats.json";
  ASSERT_EQ(runCli("render " + scene + " -m abuffer-ll -o " + gpu.string() + " --stats " + stats.string()).exitCode, 0);
  ASSERT_EQ(runCli("render " + scene + " -o " + oracle.string()).exitCode, 0);
  EXPECT_LT(rmseOf(oracle, gpu), 0.002);
  std::ifstream in(stats);
  EXPECT_EQ(nlohmann::json::parse(in)["notes"]["volumes"], "2");

  // Five visible: refused, naming the file and the entry.
  std::string renamed = volumes;  // names are unique in a scene file
  renamed.replace(renamed.find("\"red\""), 5, "\"red 2\"");
  renamed.replace(renamed.find("\"blue\""), 6, "\"blue 2\"");
  std::ofstream(dir() / "five.mfrscene") << R"({"volumes": [)" << volumes << ", " << renamed
                                         << R"(, {"file": "uniform.vtk"}]})";
  expectCleanFailure("render " + (dir() / "five.mfrscene").string(), "volumes[4].visible");
  expectCleanFailure("render " + (dir() / "five.mfrscene").string(), "five.mfrscene");
}

}  // namespace
