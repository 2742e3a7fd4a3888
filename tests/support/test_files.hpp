#pragma once
// Files and processes for tests: a fresh temporary folder (TempDir, or the TempDirTest fixture
// around one), the check that loadModel fails with one line naming the file and the reason, and a
// command line (the mfr command line, glslangValidator) run as a child process.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <ios>
#include <iterator>
#include <optional>
#include <string>
#include <system_error>

#include "mfr/error.hpp"
#include "mfr/image.hpp"
#include "mfr/io/load.hpp"

namespace mfr::test {

// A fresh folder "<prefix>-XXXXXX" (mkdtemp) in the temporary directory, removed with all it holds
// when destroyed. The owner's permissions on the folder are restored first, so a test may take
// them away (LoadModel.UnreadableFile does).
class TempDir {
 public:
  // Prefix "mfr-<test suite>" while a test runs, else "mfr-test".
  TempDir() : TempDir(defaultPrefix()) {}
  explicit TempDir(const std::string& prefix) {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) != nullptr)
      path_ = pattern;
    else
      ADD_FAILURE() << "cannot create the temporary folder " << pattern;
  }
  ~TempDir() {
    if (path_.empty()) return;
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  // Writes `bytes` as they are to the file `name` in the folder; returns its path.
  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    const std::filesystem::path p = path_ / name;
    std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p;
  }

  // Writes `bytes` gzip-compressed to the file `name` in the folder; returns its path.
  std::filesystem::path writeGz(const std::string& name, const std::string& bytes) const {
    const std::filesystem::path p = path_ / name;
    gzFile gz = gzopen(p.c_str(), "wb");
    EXPECT_NE(gz, nullptr);
    if (gz == nullptr) return p;
    EXPECT_EQ(gzwrite(gz, bytes.data(), static_cast<unsigned>(bytes.size())), static_cast<int>(bytes.size()));
    gzclose(gz);
    return p;
  }

 private:
  static std::string defaultPrefix() {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    if (test == nullptr) return "mfr-test";
    std::string prefix = std::string("mfr-") + test->test_suite_name();
    for (char& c : prefix)  // parameterised suites are named "Prefix/Suite"
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '-';
    return prefix;
  }

  std::filesystem::path path_;
};

// A fixture with a fresh temporary folder per test: made in SetUp, removed in TearDown.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_.emplace();
    ASSERT_FALSE(tmp_->path().empty());
  }
  void TearDown() override { tmp_.reset(); }

  [[nodiscard]] const std::filesystem::path& dir() const { return tmp_->path(); }
  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    return tmp_->write(name, bytes);
  }
  std::filesystem::path writeGz(const std::string& name, const std::string& bytes) const {
    return tmp_->writeGz(name, bytes);
  }

 private:
  std::optional<TempDir> tmp_;
};

// CGAL's demo meshes ship inside one tarball (Debian package libcgal-demo): extracts the one named
// `file` (data/meshes/FILE) into `dir` and returns its path, or an empty path after a failure.
inline std::filesystem::path extractCgalMesh(const TempDir& dir, const std::string& file) {
  const std::filesystem::path tarball = "/usr/share/doc/libcgal-dev/data.tar.gz";
  if (!std::filesystem::exists(tarball)) {
    ADD_FAILURE() << "missing " << tarball << " (from Debian package libcgal-demo; scripts/setup installs it)";
    return {};
  }
  const std::string member = "data/meshes/" + file;
  const std::string command = "tar -xzf '" + tarball.string() + "' -C '" + dir.path().string() + "' '" + member + "'";
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "could not extract " << member << " from " << tarball;
    return {};
  }
  return dir.path() / member;
}

// Expects loadModel(path) to throw one mfr::Error whose message is one line that starts with
// "<path>: " and contains `reason`. Loading, LoadCancelled and any other exception are failures.
// load() is the loader under test, returning a description of what it loaded (for the message
// when it should not have); expectLoadError is the case of loadModel.
inline void expectFileError(const std::filesystem::path& path, const std::string& reason,
                            const std::function<std::string()>& load) {
  try {
    const std::string loaded = load();
    ADD_FAILURE() << path << ": loaded " << loaded << ", expected an error about '" << reason << "'";
  } catch (const mfr::LoadCancelled&) {
    ADD_FAILURE() << path << ": cancelled";
  } catch (const mfr::Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
    EXPECT_EQ(what.rfind(path.string() + ": ", 0), 0u) << "does not start with the path: " << what;
    EXPECT_NE(what.find(reason), std::string::npos) << "expected '" << reason << "' in: " << what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": non-mfr exception: " << e.what();
  }
}

inline void expectLoadError(const std::filesystem::path& path, const std::string& reason) {
  expectFileError(path, reason, [&] { return std::to_string(mfr::loadModel(path).size()) + " objects"; });
}

// A whole file, decompressed when its name ends in .gz (zlib's own reader: independent of the
// loaders' code); empty when it cannot be read.
inline std::string readTestFile(const std::filesystem::path& path) {
  if (path.extension() == ".gz") {
    gzFile gz = gzopen(path.c_str(), "rb");
    if (gz == nullptr) return {};
    std::string out;
    char buf[1 << 16];
    int n = 0;
    while ((n = gzread(gz, buf, sizeof buf)) > 0) out.append(buf, static_cast<std::size_t>(n));
    gzclose(gz);
    return out;
  }
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CliResult {
  int exitCode = -1;  // the exit status, 128 + the signal that ended it, or -1: could not start
  std::string out;    // stdout + stderr
};

// Runs `command` through the shell with stderr merged into stdout.
inline CliResult runCommand(const std::string& command) {
  CliResult r;
  const std::string cmd = command + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return r;
}

#ifdef MFR_CLI
// Runs `mfr <args>`: the mfr this build made (MFR_CLI).
inline CliResult runCli(const std::string& args) {
  return runCommand(std::string(MFR_CLI) + " " + args);
}

// A temporary folder and the check every bad-input case of the command line makes.
class CliTest : public TempDirTest {
 protected:
  // Runs `mfr <args> -o dir()/<name>`, expects it to succeed, and reads the PNG back (an empty
  // image when it failed).
  mfr::ImageRGBA8 renderedPng(const std::string& args, const std::string& name) {
    const std::filesystem::path out = dir() / name;
    const CliResult r = runCli(args + " -o " + out.string());
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return r.exitCode == 0 ? mfr::readPng(out) : mfr::ImageRGBA8();
  }
  // RMSE of two PNGs as `mfr compare --metric rmse` prints it.
  double rmseOf(const std::filesystem::path& a, const std::filesystem::path& b) {
    const CliResult r = runCli("compare " + a.string() + " " + b.string() + " --metric rmse");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return std::stod(r.out.substr(r.out.find("rmse ") + 5));
  }
  // Bad input: exit code non-zero (1 or 2), no crash (< 128), one line starting "mfr: " that
  // mentions `mention`, and neither the output file (-o, in dir()) nor a temporary of it left.
  void expectCleanFailure(const std::string& args, const std::string& mention) {
    const std::filesystem::path out = dir() / "out.png";
    const CliResult r = runCli(args + " -o " + out.string());
    EXPECT_TRUE(r.exitCode == 1 || r.exitCode == 2) << "exit " << r.exitCode << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_NE(r.out.find(mention), std::string::npos) << "message does not name '" << mention << "': " << r.out;
    EXPECT_EQ(r.out.rfind("mfr: ", 0), 0u) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out)) << "partial output left behind";
    for (const auto& e : std::filesystem::directory_iterator(dir()))
      EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << "temporary left: " << e.path();
  }
};
#endif

}  // namespace mfr::test
