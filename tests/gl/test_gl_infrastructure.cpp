// The GL layer itself: context, debug output turned into errors, shader #include with errors
// reported by file and line, injected defines, pass timers.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string_view>

#include <unistd.h>
#include <filesystem>
#include <iostream>

#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/gl/objects.hpp"
#include "mfr/gl/program.hpp"
#include "mfr/gl/timer.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

// Points MFR_SHADER_DIR at a temporary folder for the test's lifetime.
class ShaderDir {
 public:
  ShaderDir() {
    fs::create_directories(tmp_.path() / "lib");
    ::setenv("MFR_SHADER_DIR", tmp_.path().c_str(), 1);
  }
  ~ShaderDir() { ::unsetenv("MFR_SHADER_DIR"); }
  ShaderDir(const ShaderDir&) = delete;
  ShaderDir& operator=(const ShaderDir&) = delete;
  void write(const std::string& name, const std::string& text) const { tmp_.write(name, text); }

 private:
  TempDir tmp_;
};

TEST(GlInfrastructure, ContextIsOpenGL45Core) {
  const gl::ContextInfo& info = context().info();
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_TRUE(info.platform == "surfaceless" || info.platform == "device") << info.platform;
  GLint major = 0, minor = 0, profile = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_GE(major * 10 + minor, 45);
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
  std::cout << "[ context ] " << info.vendor << " | " << info.renderer << " | " << info.version << " | platform "
            << info.platform << " | interlock " << (info.fragmentShaderInterlock ? "yes" : "no") << "\n";
}

TEST(GlInfrastructure, DebugOutputBecomesAnError) {
  context();
  gl::checkErrors("before");              // clean slate
  glBindBuffer(GL_ARRAY_BUFFER, 987654);  // not a buffer name: GL_INVALID_OPERATION
  try {
    gl::checkErrors("bad bind");
    FAIL() << "no error reported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad bind"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(gl::checkErrors("after"));  // reported once
}

TEST(GlInfrastructure, CompileErrorNamesIncludedFileAndLine) {
  context();
  const ShaderDir dir;
  dir.write("lib/helper.glsl", "// helper\nfloat helper() {\n  return undefinedThing;\n}\n");
  dir.write("main.frag", "// main\n#include \"lib/helper.glsl\"\nout vec4 c;\nvoid main() { c = vec4(helper()); }\n");
  try {
    gl::Program p({{GL_FRAGMENT_SHADER, "main.frag"}});
    FAIL() << "compiled";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("shaders/lib/helper.glsl:3:"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(GlInfrastructure, ErrorAfterIncludeIsAttributedToTheIncludingFile) {
  context();
  const ShaderDir dir;
  dir.write("lib/ok.glsl", "float ok() { return 1.0; }\n");
  dir.write("main.frag", "#include \"lib/ok.glsl\"\nout vec4 c;\n\nvoid main() { c = vec4(ok()) + nope; }\n");
  try {
    gl::Program p({{GL_FRAGMENT_SHADER, "main.frag"}});
    FAIL() << "compiled";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shaders/main.frag:4:"), std::string::npos) << e.what();
  }
}

TEST(GlInfrastructure, DefinesAndDefineNamedIncludes) {
  context();
  const ShaderDir dir;
  dir.write("lib/a.glsl", "float pick() { return VALUE; }\n");
  dir.write("main.frag", "#include CHOSEN\nout vec4 c;\nvoid main() { c = vec4(pick()); }\n");
  EXPECT_NO_THROW(gl::Program({{GL_FRAGMENT_SHADER, "main.frag"}}, {{"CHOSEN", "\"lib/a.glsl\""}, {"VALUE", "0.5"}}));
  EXPECT_THROW(gl::Program({{GL_FRAGMENT_SHADER, "main.frag"}}), Error);  // CHOSEN undefined
  EXPECT_THROW(gl::shaderSource("missing.frag"), Error);
}

TEST(GlInfrastructure, PassTimerReportsEveryPassInOrder) {
  context();
  for (bool finish : {false, true}) {
    gl::PassTimer timer(finish);
    timer.begin("a");
    glFinish();
    timer.begin("b");  // begin closes the open pass
    timer.end();
    timer.begin("a");  // same name again: summed
    timer.end();
    const auto passes = timer.collect();
    ASSERT_EQ(passes.size(), 2u);
    EXPECT_EQ(passes[0].first, "a");
    EXPECT_EQ(passes[1].first, "b");
    for (const auto& [name, ms] : passes) EXPECT_TRUE(ms >= 0.0 && ms < 10000.0) << name << " " << ms;
  }
}

// llvmpipe's buffers and textures are main memory, checked against what is available before each
// allocation (gl/objects.cpp). The checks add up because llvmpipe zero-fills storage when it is
// created: the first allocation is resident before the second asks, so two that each fit but not
// together are refused at the second, and memory given back counts again.
TEST(GlInfrastructure, SoftwareStorageCountsTogetherAgainstTheMemoryLimit) {
  context();
  const std::string_view renderer(reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  if (renderer.find("llvmpipe") == std::string_view::npos)
    GTEST_SKIP() << "a hardware driver reports GL_OUT_OF_MEMORY itself: " << renderer;
  std::uint64_t size = 0, residentPages = 0;
  std::ifstream("/proc/self/statm") >> size >> residentPages;
  ASSERT_GT(residentPages, 0u);
  constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
  const std::uint64_t residentMiB = residentPages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) / kMiB;
  ::setenv("MFR_MEMORY_LIMIT_MIB", std::to_string(residentMiB + 400).c_str(), 1);
  struct Unset {
    ~Unset() { ::unsetenv("MFR_MEMORY_LIMIT_MIB"); }
  } unset;
  const auto refusal = [](auto allocate) {
    try {
      allocate();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(allocated)");
  };
  {
    gl::Buffer first = gl::createBuffer(256 * kMiB);  // 400 MiB left: fits
    const std::string second = refusal([&] { gl::createBuffer(256 * kMiB); });
    EXPECT_NE(second.find("would take 256 MiB more memory; only "), std::string::npos) << second;
    // A texture of the same size (8192² texels of 4 bytes) is refused the same way.
    const std::string texture = refusal([&] { gl::createTexture2D(GL_R32UI, 8192, 8192); });
    EXPECT_NE(texture.find("would take 256 MiB more memory; only "), std::string::npos) << texture;
  }
  glFinish();  // the first buffer is deleted: its memory counts as available again
  EXPECT_EQ(refusal([&] { gl::Buffer again = gl::createBuffer(256 * kMiB); }), "(allocated)");
}

}  // namespace
}  // namespace mfr::test
