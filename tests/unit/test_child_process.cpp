// The child process that assimp and Open CASCADE run in (mfrcore/src/io/child_process.*): what
// the work returns, throws, reports, and how it dies, each comes back to this process as one
// result or one line; and objects survive the trip as bytes.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "../../mfrcore/src/io/child_process.hpp"
#include "mfr/error.hpp"

namespace {

using mfr::LoadProgress;
using mfr::io::ChildLibrary;
using mfr::io::runInChild;

const ChildLibrary kLibrary{"fmt", "the library"};

// The message runInChild throws for `work`, or "" (and a failure) when it returns.
std::string errorOf(const std::function<std::string(const LoadProgress&)>& work) {
  try {
    (void)runInChild("in.fmt", kLibrary, {}, work);
  } catch (const mfr::Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "the work returned";
  return "";
}

// Sets an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) { setenv(name, value.c_str(), 1); }
  ~ScopedEnv() { unsetenv(name_); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
};

std::uint64_t residentMiB() {
  std::uint64_t size = 0, residentPages = 0;
  std::ifstream("/proc/self/statm") >> size >> residentPages;
  return residentPages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) / (1024 * 1024);
}

TEST(ChildProcess, ResultsComeBackWhole) {
  // Bytes of every value, and more than a pipe holds at once (64 KiB on Linux).
  std::string bytes(16u << 20, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 2654435761u) >> 13);
  const auto result = runInChild("in.fmt", kLibrary, {}, [&](const LoadProgress&) { return bytes; });
  ASSERT_TRUE(result.has_value());
  EXPECT_TRUE(*result == bytes);
  const auto empty = runInChild("in.fmt", kLibrary, {}, [](const LoadProgress&) { return std::string(); });
  ASSERT_TRUE(empty.has_value());
  EXPECT_TRUE(empty->empty());
}

TEST(ChildProcess, ErrorsAndCrashesAreOneLine) {
  // The work's own mfr::Error, as it is.
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string { throw mfr::Error("in.fmt", "bad header"); }),
            "in.fmt: bad header");
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string { throw std::runtime_error("vector::at"); }),
            "in.fmt: cannot read fmt: the library failed (vector::at)");
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string { throw 3; }),
            "in.fmt: cannot read fmt: the library failed");
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string {
              std::raise(SIGSEGV);
              return "";
            }),
            "in.fmt: cannot read fmt: the library crashed (Segmentation fault; corrupt or truncated file?)");
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string { std::abort(); }),
            "in.fmt: cannot read fmt: the library crashed (Aborted; corrupt or truncated file?)");
  // Killed from outside (the out-of-memory killer's SIGKILL) or stopped: not blamed on the file.
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string {
              std::raise(SIGKILL);
              return "";
            }),
            "in.fmt: cannot read fmt: the process reading it with the library was stopped from outside (Killed: by "
            "the system when memory ran out, or by another program)");
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string {
              std::raise(SIGTERM);
              return "";
            }),
            "in.fmt: cannot read fmt: the process reading it with the library was stopped from outside (Terminated)");
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string { _exit(3); }),
            "in.fmt: cannot read fmt: the library ended without a result (corrupt or truncated file?)");
}

TEST(ChildProcess, TheTimeLimitCountsFromTheLastReport) {
  const ScopedEnv limit("MFR_IMPORT_TIMEOUT_S", "1");
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(errorOf([](const LoadProgress&) -> std::string {
              for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));
            }),
            "in.fmt: cannot read fmt: the library did not finish in 1 s (corrupt or truncated file?)");
  EXPECT_EQ(errorOf([](const LoadProgress& progress) -> std::string {
              progress.step(0.5);
              for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));
            }),
            "in.fmt: cannot read fmt: the library made no progress for 1 s (corrupt or truncated file?)");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  // 2.5 s of work that reports every 0.25 s is not cut off.
  const auto result = runInChild("in.fmt", kLibrary, {}, [](const LoadProgress& progress) {
    for (int i = 1; i <= 10; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      progress.step(i / 10.0);
    }
    return std::string("done");
  });
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(*result, "done");
}

TEST(ChildProcess, TheMemoryLimitIsOneLine) {
  // 300 MiB above what this process holds; the work asks for 2 GiB.
  const ScopedEnv limit("MFR_MEMORY_LIMIT_MIB", std::to_string(300 + residentMiB()));
  const std::string error = errorOf([](const LoadProgress&) {
    std::vector<char> big(std::size_t{2} << 30, 'x');
    return std::string(big.begin(), big.begin() + 1);
  });
  EXPECT_EQ(error.rfind("in.fmt: cannot read fmt: the library needed more than the ", 0), 0u) << error;
  EXPECT_NE(error.find(" available (a corrupt file, or one too large for this machine)"), std::string::npos) << error;
}

TEST(ChildProcess, ProgressReachesThisProcessAndCancelKillsTheChild) {
  std::vector<double> reports;
  const LoadProgress progress{[&](double f) {
                                reports.push_back(f);
                                return true;
                              },
                              0.5, 1.0};
  const auto result = runInChild("in.fmt", kLibrary, progress, [](const LoadProgress& child) {
    for (const double f : {0.0, 0.25, 0.5, 1.0}) child.step(f);
    return std::string("ok");
  });
  ASSERT_TRUE(result.has_value());
  ASSERT_FALSE(reports.empty());
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  for (const double f : {0.625, 0.75, 1.0})  // the child's fractions, in the part this progress covers
    EXPECT_NE(std::find(reports.begin(), reports.end(), f), reports.end()) << f;
  // Cancelled at the child's half-way report: the work never gets to its end (which would hang).
  const auto start = std::chrono::steady_clock::now();
  const LoadProgress cancelling{[](double f) { return f < 0.5; }};
  EXPECT_THROW((void)runInChild("in.fmt", kLibrary, cancelling,
                                [](const LoadProgress& child) -> std::string {
                                  child.step(0.5);
                                  for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));
                                }),
               mfr::LoadCancelled);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(ChildProcess, BadTimeLimitsAreRefused) {
  for (const char* value : {"0", "-1", "86401", "1.5", "x", "99999999999999999999", " 5", "+5", "5 "}) {
    const ScopedEnv limit("MFR_IMPORT_TIMEOUT_S", value);
    EXPECT_EQ(errorOf([](const LoadProgress&) { return std::string(); }),
              std::string("in.fmt: MFR_IMPORT_TIMEOUT_S=") + value + ": expected whole seconds, 1 to 86400");
  }
}

TEST(PackObjects, ObjectsSurviveAsBytes) {
  auto shared = std::make_shared<mfr::Mesh>();
  shared->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  shared->normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  shared->colors = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 0.5f}};
  shared->indices = {0, 1, 2};
  shared->fields = {{"pressure", false, 1, {1.0f, 2.0f, 3.0f}}, {"id", true, 3, {7.0f, 8.0f, 9.0f}}};
  shared->scalars = {1.0f, 2.0f, 3.0f};
  auto plain = std::make_shared<mfr::Mesh>();
  plain->positions = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  plain->normals = {{0, 0, -1}, {0, 0, -1}, {0, 0, -1}};
  plain->indices = {0, 2, 1};
  std::vector<mfr::Object> objects(4);
  objects[0].name = "first";
  objects[0].mesh = shared;
  objects[0].transform[3] = glm::dvec4(1.5, -2.0, 1e-300, 1.0);
  objects[0].material.color = {0.1f, 0.2f, 0.3f, 0.4f};
  objects[0].material.fieldColors = mfr::FieldColors{"pressure", "viridis", {-1.0, 4.0}};
  objects[1].name = "second instance of the first's mesh";
  objects[1].mesh = shared;
  objects[1].visible = false;
  objects[2].name = "plain";
  objects[2].mesh = plain;
  objects[2].material.vertexColors = false;
  objects[3].name = std::string("no mesh\0here", 12);
  const std::vector<std::string> notes{"in.fmt: one note", ""};
  std::vector<std::string> notesBack{"a note before"};
  const std::vector<mfr::Object> back = mfr::io::unpackObjects(mfr::io::packObjects(objects, notes), &notesBack);
  EXPECT_EQ(notesBack, (std::vector<std::string>{"a note before", "in.fmt: one note", ""}));
  ASSERT_EQ(back.size(), objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(back[i].name, objects[i].name);
    EXPECT_EQ(back[i].transform, objects[i].transform);
    EXPECT_EQ(back[i].material.color, objects[i].material.color);
    EXPECT_EQ(back[i].material.vertexColors, objects[i].material.vertexColors);
    EXPECT_EQ(back[i].material.fieldColors, objects[i].material.fieldColors);
    EXPECT_EQ(back[i].visible, objects[i].visible);
    ASSERT_EQ(back[i].mesh == nullptr, objects[i].mesh == nullptr);
    if (!objects[i].mesh) continue;
    EXPECT_EQ(back[i].mesh->positions, objects[i].mesh->positions);
    EXPECT_EQ(back[i].mesh->normals, objects[i].mesh->normals);
    EXPECT_EQ(back[i].mesh->colors, objects[i].mesh->colors);
    EXPECT_EQ(back[i].mesh->indices, objects[i].mesh->indices);
    EXPECT_EQ(back[i].mesh->fields, objects[i].mesh->fields);
    EXPECT_EQ(back[i].mesh->scalars, objects[i].mesh->scalars);
  }
  EXPECT_EQ(back[0].mesh, back[1].mesh) << "a shared mesh stays shared";
  EXPECT_NE(back[0].mesh, back[2].mesh);
  // Bytes cut short, or with more after them, are refused (never read past the end).
  const std::string bytes = mfr::io::packObjects(objects);
  for (const std::size_t n : {std::size_t{0}, std::size_t{5}, bytes.size() / 2, bytes.size() - 1})
    EXPECT_THROW((void)mfr::io::unpackObjects(bytes.substr(0, n)), std::logic_error) << n;
  EXPECT_THROW((void)mfr::io::unpackObjects(bytes + "x"), std::logic_error);
}

}  // namespace
