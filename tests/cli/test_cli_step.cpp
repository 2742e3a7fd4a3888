// mfr on STEP files, end to end: a bad file gives one line naming it, a non-zero exit and no
// output file (Open CASCADE's own messages must not reach the terminal); a real CAD part renders
// with the oracle and with a GPU method alike, with more than one fragment in some pixels.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "mfr/image.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kLinkrods = "/usr/share/opencascade/data/step/linkrods.step";
const fs::path kScrew = "/usr/share/opencascade/data/step/screw.step";

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

class CliStep : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mfr-cli-step-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    if (!fs::exists(kLinkrods) || !fs::exists(kScrew))
      ADD_FAILURE() << "missing the occt-misc STEP samples (scripts/setup installs them)";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path file(const std::string& name, const std::string& content) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
  void expectOneLineFailure(const Result& r, const std::string& mention) {
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_EQ(r.out.rfind("mfr: ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find(mention), std::string::npos) << r.out;
  }
  fs::path dir_;
};

TEST_F(CliStep, BadFilesFailWithOneLine) {
  std::ifstream in(kScrew, std::ios::binary);
  const std::string screw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path cut = file("cut.step", screw.substr(0, screw.size() / 3));
  const fs::path junk = file("junk.stp", "ISO-10303-21;\nthis is not STEP at all\n");
  for (const fs::path& bad : {cut, junk}) {
    SCOPED_TRACE(bad.filename().string());
    expectOneLineFailure(run("info " + bad.string()), bad.string() + ": not a readable STEP file");
    const fs::path png = dir_ / "out.png";
    expectOneLineFailure(run("render " + bad.string() + " -s 16x16 -o " + png.string()), bad.string());
    EXPECT_FALSE(fs::exists(png)) << "partial output left behind";
  }
}

TEST_F(CliStep, LinkrodsRendersWithOracleAndGpu) {
  const fs::path json = dir_ / "info.json", oracle = dir_ / "oracle.png", gpu = dir_ / "gpu.png",
                 stats = dir_ / "stats.json";
  Result r = run("info " + kLinkrods.string() + " -s 48x48 --view iso --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  std::ifstream in(json);
  const nlohmann::json info = nlohmann::json::parse(in);
  EXPECT_EQ(info.at("parts"), 1);
  EXPECT_GT(info.at("triangles").get<int>(), 100);
  // Seen through, a solid is entered and left: two or more fragments in some pixels.
  EXPECT_GE(info.at("depth_complexity").at("max").get<int>(), 2);

  ASSERT_EQ(run("render " + kLinkrods.string() + " -s 48x48 --view iso --opacity 0.4 -o " + oracle.string()).exitCode,
            0);
  r = run("render " + kLinkrods.string() + " -s 48x48 --view iso --opacity 0.4 -m abuffer-ll -o " + gpu.string() +
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
  r = run("compare " + oracle.string() + " " + gpu.string() + " --metric rmse");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_LT(std::stod(r.out.substr(r.out.find("rmse ") + 5)), 0.02) << r.out;
}

}  // namespace
