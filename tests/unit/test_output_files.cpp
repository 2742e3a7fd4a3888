// Outputs are written whole or not at all (io_util.hpp): a command's several outputs together, so
// that one that fails leaves none of the others behind (a bug hunt: mfr render's PNG stayed when
// its --stats could not be written on a full disk).
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io_util.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

class OutputFiles : public mfr::test::TempDirTest {};

std::vector<std::string> namesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

TEST_F(OutputFiles, SeveralOutputsAreWrittenAllOrNone) {
  const fs::path png = dir() / "a.png", json = dir() / "a.json";
  mfr::writeFilesAtomically({{png, "first"}, {json, "second"}});
  EXPECT_EQ(mfr::readFile(png), "first");
  EXPECT_EQ(mfr::readFile(json), "second");
  // A file-size limit stands in for a full disk: the second output cannot be written.
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails (EFBIG) instead
  rlimit small = old;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const fs::path png2 = dir() / "b.png", json2 = dir() / "b.json";
  std::string message;
  try {
    mfr::writeFilesAtomically({{png2, "fits"}, {json2, std::string(8192, 'x')}});
  } catch (const mfr::Error& e) {
    message = e.what();
  }
  // Replacing existing outputs: the old ones stay as they were.
  std::string replaceMessage;
  try {
    mfr::writeFilesAtomically({{png, "new first"}, {json, std::string(8192, 'y')}});
  } catch (const mfr::Error& e) {
    replaceMessage = e.what();
  }
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &old), 0);
  std::signal(SIGXFSZ, previous);
  EXPECT_EQ(message, json2.string() + ": write failed (disk full?)");
  EXPECT_EQ(replaceMessage, json.string() + ": write failed (disk full?)");
  EXPECT_FALSE(fs::exists(png2)) << "the first output was left behind";
  EXPECT_FALSE(fs::exists(json2));
  EXPECT_EQ(mfr::readFile(png), "first");
  EXPECT_EQ(mfr::readFile(json), "second");
  // No temporary is left either.
  std::vector<std::string> names = namesIn(dir());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a.json", "a.png"}));
  // A bad second path is refused before the first is written.
  EXPECT_THROW(mfr::writeFilesAtomically({{png2, "x"}, {dir() / "no" / "b.json", "y"}}), mfr::Error);
  EXPECT_FALSE(fs::exists(png2));
}

}  // namespace
