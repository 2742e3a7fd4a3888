// Hybrid transparency on the GPU (Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent
// transparency", The Visual Computer 2022, §3.3; Maule et al., I3D 2013): the k+-buffer's core
// (k nearest, sorted in resolve) + its tail hook (MFR_SSBO_TAIL), composited by ops/hybrid.glsl,
// equals the oracle's compositeHybrid for the same uniform k.
#include <gtest/gtest.h>

#include <iostream>
#include <string>

#include "gl_fixture.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

constexpr int kW = 96, kH = 72;

const SampleReference& reference() {
  return sampleReference("front", kW, kH);
}

RenderRequest hybridRequest(const std::string& method, int k, bool tail = true) {
  RenderRequest req;
  req.method = method;
  req.operation = "hybrid";
  req.width = kW;
  req.height = kH;
  req.params = {{"k", std::to_string(k)}, {"tail", tail ? "true" : "false"}};
  return req;
}

class HybridGpu : public ::testing::TestWithParam<std::string> {};

TEST_P(HybridGpu, EqualsTheOracleHybrid) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  for (int k : {1, 2, 4, 8}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    const ImageRGBA8 expected = compositeHybrid(ref.oracle, static_cast<std::uint32_t>(k), ref.scene.background);
    const RenderOutput out = gpu.render(ref.camera, hybridRequest(GetParam(), k));
    EXPECT_EQ(out.stats.operation, "hybrid");
    EXPECT_EQ(out.stats.lockFailures, 0u);
    const ImageComparison c = compareImages(ref.oracle, expected, out.image, 2);
    EXPECT_GT(c.compared, static_cast<std::size_t>(kW * kH) * 7 / 10);
    EXPECT_GE(c.fraction(), 0.999) << "max difference " << c.maxDifference;
    std::cout << "[ hybrid ] " << GetParam() << " k=" << k << ": " << c.within << " of " << c.compared
              << " pixels within 2/255, max difference " << c.maxDifference << "/255\n";
    // The tail must be at work: the plain k-buffer ("oit" on the same k nearest) differs.
    RenderRequest plain = hybridRequest(GetParam(), k);
    plain.operation = "oit";
    plain.params["tail"] = "false";  // only hybrid reads it (refused elsewhere)
    const ImageComparison vsPlain = compareImages(ref.oracle, gpu.render(ref.camera, plain).image, out.image, 2);
    EXPECT_LT(vsPlain.within, vsPlain.compared);
    if (k <= 2) {
      EXPECT_LT(vsPlain.fraction(), 0.99);
    }
    std::cout << "[ hybrid ]   differs from the plain k-buffer on " << vsPlain.compared - vsPlain.within << " pixels\n";
  }
}

INSTANTIATE_TEST_SUITE_P(Hybrid, HybridGpu, ::testing::Values("kplus-array", "kplus-heap", "kplus-sbuffer", "kbuffer"),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                           std::string n = p.param;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

TEST(Hybrid, RefusedWithoutATail) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  EXPECT_THROW(gpu.render(ref.camera, hybridRequest("kplus-array", 4, false)), Error);
  RenderRequest abuffer;
  abuffer.method = "abuffer-ll";
  abuffer.operation = "hybrid";
  abuffer.width = kW;
  abuffer.height = kH;
  try {
    gpu.render(ref.camera, abuffer);
    ADD_FAILURE() << "abuffer-ll accepted --op hybrid";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("--op hybrid"), std::string::npos);
  }
  RenderRequest unknown = hybridRequest("kplus-array", 4);
  unknown.operation = "nope";
  EXPECT_THROW(gpu.render(ref.camera, unknown), Error);
}

// F(M)/fkb's byte model is what kplus-array with the tail really allocates: for a budget M, the
// chosen uniform k fits (Stats::bytesAllocated = M(k) ≤ M) and k + 1 would not.
TEST(Hybrid, UniformKForABudgetFits) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  const std::uint64_t pixels = static_cast<std::uint64_t>(kW) * kH;
  const KBufferMemoryModel model = kplusArrayMemoryModel(pixels);
  for (std::uint64_t budget : {model.bytes(1), model.bytes(3) + 1000, model.bytes(6) - 1}) {
    const std::uint32_t k = largestUniformK(model, budget);
    ASSERT_GE(k, 1u);
    const RenderOutput out = gpu.render(ref.camera, hybridRequest("kplus-array", static_cast<int>(k)));
    EXPECT_EQ(out.stats.bytesAllocated, model.bytes(k));
    EXPECT_LE(out.stats.bytesAllocated, budget);
    EXPECT_GT(model.bytes(k + 1), budget);
    EXPECT_EQ(slotBudget(model, budget) / pixels, k);
  }
}

}  // namespace
}  // namespace mfr::test
