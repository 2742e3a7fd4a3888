// The fragment-shader-interlock path of every k-buffer store pass (sync=interlock) cannot run on
// llvmpipe, which lacks the extension. Short of a GPU, each variant is checked by an independent
// GLSL front end, Khronos' glslangValidator: the preprocessed pass (our #include and #define
// expansion, exactly what the driver would receive) must compile with GL_ARB_fragment_shader_
// interlock, which includes glslang's rule that beginInvocationInterlockARB sits in main() outside
// any flow control. The spin-lock variants are compiled the same way, and a deliberately misplaced
// interlock must be rejected (so the check can fail). glslang 12 knows only the ARB spelling; the
// NV and INTEL ones are not checked here.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mfr/gl/program.hpp"
#include "test_files.hpp"

namespace {

struct Compiled {
  int exitCode = -1;
  std::string log;
};

Compiled glslang(const std::string& source, const std::string& name) {
  const mfr::test::TempDir tmp;
  const std::filesystem::path path = tmp.write(name + ".frag", source);
  const mfr::test::CliResult r = mfr::test::runCommand(std::string(MFR_GLSLANG) + " " + path.string());
  return {r.exitCode, r.out};
}

struct Variant {
  std::string pass;
  mfr::gl::Defines defines;
  std::string name;
};

std::vector<Variant> storeVariants() {
  std::vector<Variant> v;
  const std::vector<std::pair<std::string, mfr::gl::Defines>> passes{
      {"methods/kbuffer/store.geom.frag", {}},
      {"methods/kplus-array/store.geom.frag", {{"MFR_KB_CULLING", "1"}}},
      {"methods/kplus-array/store.geom.frag", {{"MFR_KB_REVISED", "1"}}},
      {"methods/kplus-array/store.geom.frag",
       {{"MFR_KB_VARIABLE", "1"}, {"MFR_KB_CULLING", "1"}, {"MFR_KB_TAIL", "1"}}},
      {"methods/kplus-heap/store.geom.frag", {{"MFR_KB_CULLING", "1"}, {"MFR_KB_TAIL", "1"}}},
      {"methods/kplus-heap/store.geom.frag", {{"MFR_KB_VARIABLE", "1"}}},
      {"methods/kpeel/store.geom.frag", {}},
  };
  for (std::size_t i = 0; i < passes.size(); ++i) {
    mfr::gl::Defines interlock = passes[i].second;
    interlock["MFR_SYNC_INTERLOCK"] = "1";
    interlock["MFR_INTERLOCK_ARB"] = "1";
    v.push_back({passes[i].first, interlock, "interlock" + std::to_string(i)});
    v.push_back({passes[i].first, passes[i].second, "spinlock" + std::to_string(i)});
    mfr::gl::Defines buffer = passes[i].second;
    buffer["MFR_KB_LOCKS_IN_BUFFER"] = "1";
    v.push_back({passes[i].first, buffer, "lockbuffer" + std::to_string(i)});
  }
  return v;
}

TEST(InterlockShaders, EveryStorePassCompilesWithTheArbExtension) {
  for (const Variant& v : storeVariants()) {
    std::string defines;
    for (const auto& [k, value] : v.defines) defines += " " + k;
    SCOPED_TRACE(v.pass + defines);
    const std::string source = mfr::gl::preprocessShader(v.pass, v.defines);
    if (v.defines.count("MFR_SYNC_INTERLOCK")) {
      ASSERT_NE(source.find("beginInvocationInterlockARB()"), std::string::npos);
      ASSERT_NE(source.find("#extension GL_ARB_fragment_shader_interlock : require"), std::string::npos);
    }
    const Compiled c = glslang(source, v.name);
    EXPECT_EQ(c.exitCode, 0) << c.log;
  }
}

TEST(InterlockShaders, MisplacedInterlockIsRejected) {
  std::string source = mfr::gl::preprocessShader("methods/kplus-array/store.geom.frag",
                                                 {{"MFR_SYNC_INTERLOCK", "1"}, {"MFR_INTERLOCK_ARB", "1"}});
  const std::string call = "  KB_INTERLOCK_BEGIN();";
  const auto at = source.find(call);
  ASSERT_NE(at, std::string::npos);
  source.replace(at, call.size(), "  if (action == KB_LOCK) KB_INTERLOCK_BEGIN();");  // inside flow control
  const Compiled c = glslang(source, "misplaced");
  EXPECT_NE(c.exitCode, 0);
  EXPECT_NE(c.log.find("flow control"), std::string::npos) << c.log;
}

}  // namespace
