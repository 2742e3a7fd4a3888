// assimp 5.2 crashes, hangs or allocates without end on some truncated or corrupt files (a bug
// hunt's cases, cut from assimp's own test models). mfr imports each file in a child process
// (io/assimp_loader.cpp): each case is one error naming the file, and this process lives on.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kModels = "/usr/share/assimp/models";

std::string bytesOf(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) ADD_FAILURE() << "missing " << p << " (from Debian package assimp-testmodels; scripts/setup installs it)";
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The error loading `p` gives, or "" (and a failure) when it loads.
std::string errorOf(const fs::path& p) {
  try {
    (void)mfr::loadModel(p);
  } catch (const mfr::Error& e) {
    return e.what();
  }
  ADD_FAILURE() << p << " loaded";
  return "";
}

std::uint64_t residentMiB() {
  std::uint64_t size = 0, residentPages = 0;
  std::ifstream("/proc/self/statm") >> size >> residentPages;
  return residentPages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) / (1024 * 1024);
}

class AssimpGuard : public mfr::test::TempDirTest {};

TEST_F(AssimpGuard, CrashesAreOneLineErrors) {
  // A truncated binary X file: an uncaught DeadlyImportError, abort (exit 134).
  const fs::path x = write("cut.x", bytesOf(kModels / "X/test_cube_binary.x").substr(0, 2534));
  EXPECT_EQ(errorOf(x),
            x.string() + ": cannot read x: the importer (assimp) crashed (Aborted; corrupt or truncated file?)");
  // A truncated Half-Life MDL and an ASE with one keyword misspelt: SIGSEGV (exit 139).
  const fs::path mdl = write("cut.mdl", bytesOf(kModels / "MDL/MDL (HL1)/chrome_sphere.mdl").substr(0, 4662));
  EXPECT_EQ(errorOf(mdl),
            mdl.string() +
                ": cannot read mdl: the importer (assimp) crashed (Segmentation fault; corrupt or truncated file?)");
  std::string ase = bytesOf(kModels / "ASE/ThreeCubesGreen.ASE");
  const std::size_t face = ase.find("*MESH_FACE    8:");
  ASSERT_NE(face, std::string::npos);
  ase.replace(face, 10, "*MESH_FoCE");
  const fs::path misspelt = write("misspelt.ase", ase);
  EXPECT_NE(errorOf(misspelt).find("the importer (assimp) crashed (Segmentation fault"), std::string::npos);
  // The whole file still loads (the check is not a refusal of the format).
  EXPECT_EQ(mfr::loadModel(kModels / "ASE/ThreeCubesGreen.ASE").size(), 3u);
}

TEST_F(AssimpGuard, HangsAndRunawayMemoryEnd) {
  // A truncated SMD file: assimp loops for ever at 100 % CPU. The time limit (120 s by default
  // since assimp's last progress report) is 2 s here.
  const fs::path smd = write("cut.smd", bytesOf(kModels / "SMD/triangle.smd").substr(0, 39));
  ASSERT_EQ(setenv("MFR_IMPORT_TIMEOUT_S", "2", 1), 0);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(
      errorOf(smd),
      smd.string() + ": cannot read smd: the importer (assimp) made no progress for 2 s (corrupt or truncated file?)");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  ASSERT_EQ(setenv("MFR_IMPORT_TIMEOUT_S", "0", 1), 0);
  EXPECT_EQ(errorOf(smd), smd.string() + ": MFR_IMPORT_TIMEOUT_S=0: expected whole seconds, 1 to 86400");
  ASSERT_EQ(unsetenv("MFR_IMPORT_TIMEOUT_S"), 0);
  // A DAE with one letter in an index list: assimp allocates without end (3 GB in 14 s, never
  // done). The memory limit here: 600 MiB above what this process holds.
  std::string dae = bytesOf(kModels / "Collada/sphere.dae");
  ASSERT_GT(dae.size(), 35557u);
  dae[35557] = 'x';
  const fs::path runaway = write("runaway.dae", dae);
  ASSERT_EQ(setenv("MFR_MEMORY_LIMIT_MIB", std::to_string(600 + residentMiB()).c_str(), 1), 0);
  const std::string error = errorOf(runaway);
  ASSERT_EQ(unsetenv("MFR_MEMORY_LIMIT_MIB"), 0);
  EXPECT_NE(error.find(runaway.string() + ": cannot read dae: the importer (assimp) needed more than the "),
            std::string::npos)
      << error;
}

}  // namespace
