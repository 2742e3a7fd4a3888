// The maps behind an image (viewer views, budget features): the GPU depth complexity n(p) equals
// the oracle's exact per-pixel fragment counts, and a k-buffer's k(p) map is its real per-pixel
// capacity (uniform k, or min(n(p), k) for the memory-aware S-buffer variant).
#include <gtest/gtest.h>

#include <algorithm>

#include "gl_fixture.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

constexpr int kW = 80, kH = 64;

const SampleReference& reference() {
  return sampleReference("iso", kW, kH);
}

TEST(PixelMaps, DepthComplexityEqualsTheOracle) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  const std::vector<std::uint32_t> n = gpu.depthComplexity(ref.camera, kW, kH);
  ASSERT_EQ(n.size(), static_cast<std::size_t>(kW) * kH);
  std::size_t compared = 0, equal = 0;
  std::uint32_t deepest = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (ref.oracle.isAmbiguous(x, y)) continue;
      ++compared;
      equal += n[ref.oracle.index(x, y)] == ref.oracle.count(x, y);
      deepest = std::max(deepest, n[ref.oracle.index(x, y)]);
    }
  EXPECT_GT(compared, static_cast<std::size_t>(kW * kH) / 2);
  EXPECT_EQ(equal, compared);
  EXPECT_GT(deepest, 8u);  // the sample is deep: a map of zeros or ones would not pass
}

TEST(PixelMaps, KMapIsTheCapacityOfTheLastFrame) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  EXPECT_TRUE(gpu.kMap().empty());  // before any frame
  RenderRequest req;
  req.width = kW;
  req.height = kH;
  req.method = "abuffer-ll";
  gpu.render(ref.camera, req);
  EXPECT_TRUE(gpu.kMap().empty());  // no per-pixel capacity

  req.method = "kplus-array";
  req.params = {{"k", "5"}};
  gpu.render(ref.camera, req);
  const std::vector<std::uint32_t> uniform = gpu.kMap();
  ASSERT_EQ(uniform.size(), static_cast<std::size_t>(kW) * kH);
  EXPECT_TRUE(std::all_of(uniform.begin(), uniform.end(), [](std::uint32_t k) { return k == 5; }));

  req.method = "kplus-sbuffer";
  req.params = {{"k", "4"}};
  gpu.render(ref.camera, req);
  const std::vector<std::uint32_t> variable = gpu.kMap();
  ASSERT_EQ(variable.size(), static_cast<std::size_t>(kW) * kH);
  std::size_t compared = 0, equal = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (ref.oracle.isAmbiguous(x, y)) continue;
      ++compared;
      equal += variable[ref.oracle.index(x, y)] == std::min(ref.oracle.count(x, y), 4u);
    }
  EXPECT_EQ(equal, compared);
}

}  // namespace
}  // namespace mfr::test
