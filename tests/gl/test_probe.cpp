// The GPU half of the pixel probe: a capture of a region holds exactly the lists the whole image's
// capture holds there, and matched against the oracle's probe an exact method holds every
// fragment while a k⁺-buffer holds the k nearest — on the built-in sample, pixels off edges. And
// the hybrid split the probe reports (its core the held fragments, its tail the rest) predicts the
// colour the budget methods and a k-buffer with its tail draw.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/probe.hpp"

namespace mfr::test {
namespace {

constexpr int kW = 80, kH = 64;

TEST(ProbeGpu, RegionCaptureEqualsTheWholeImageCapture) {
  context();
  const SampleReference& ref = sampleReference("iso", kW, kH);
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  for (const char* method : {"abuffer-ll", "kplus-array"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.width = kW;
    req.height = kH;
    if (std::string(method) == "kplus-array") req.params["k"] = "4";
    const CapturedLists all = gpu.capture(ref.camera, req, 32);
    const PixelRect region{23, 17, 9, 7};
    const CapturedLists part = gpu.capture(ref.camera, req, 32, region);
    ASSERT_EQ(part.width, 9);
    ASSERT_EQ(part.height, 7);
    ASSERT_EQ(part.counts.size(), 63u);
    std::size_t fragments = 0;
    for (int y = region.y; y < region.y + region.height; ++y)
      for (int x = region.x; x < region.x + region.width; ++x) {
        ASSERT_EQ(part.count(x, y), all.count(x, y)) << x << "," << y;
        for (std::uint32_t i = 0; i < std::min<std::uint32_t>(part.count(x, y), 32); ++i) {
          EXPECT_EQ(part.pixel(x, y)[i].depth, all.pixel(x, y)[i].depth) << x << "," << y << " #" << i;
          EXPECT_EQ(part.pixel(x, y)[i].color, all.pixel(x, y)[i].color) << x << "," << y << " #" << i;
          ++fragments;
        }
      }
    EXPECT_GT(fragments, 100u);  // the region is not empty space
  }
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = kW;
  req.height = kH;
  EXPECT_THROW((void)gpu.capture(ref.camera, req, 8, PixelRect{kW - 2, 0, 3, 1}), Error);
  EXPECT_THROW((void)gpu.capture(ref.camera, req, 8, PixelRect{0, kH, 1, 1}), Error);
}

TEST(ProbeGpu, ExactMethodsHoldEveryFragmentAndKBuffersTheNearest) {
  context();
  const SampleReference& ref = sampleReference("iso", kW, kH);
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  struct Case {
    const char* method;
    std::uint32_t k;  // 0: every fragment
  };
  for (const Case c : {Case{"abuffer-ll", 0}, Case{"abuffer-sbuffer", 0}, Case{"kplus-array", 3}, Case{"kbuffer", 2}}) {
    SCOPED_TRACE(c.method);
    RenderRequest req;
    req.method = c.method;
    req.width = kW;
    req.height = kH;
    if (c.k > 0) req.params["k"] = std::to_string(c.k);
    std::size_t probed = 0, deep = 0;
    for (int y = 4; y < kH; y += 9)
      for (int x = 3; x < kW; x += 7) {
        if (ref.oracle.isAmbiguous(x, y) || ref.oracle.count(x, y) == 0) continue;
        PixelProbe probe = probePixel(ref.scene, ref.camera, kW, kH, x, y);
        ASSERT_EQ(probe.fragments.size(), ref.oracle.count(x, y));
        const CapturedLists lists = gpu.capture(ref.camera, req, 64, PixelRect{x, y, 1, 1});
        matchCapture(probe, {lists.pixel(x, y), std::min<std::size_t>(lists.count(x, y), 64)}, lists.count(x, y));
        const std::size_t n = probe.fragments.size();
        const std::size_t want = c.k == 0 ? n : std::min<std::size_t>(n, c.k);
        EXPECT_EQ(probe.methodCount, want) << x << "," << y;
        EXPECT_EQ(probe.unmatched, 0u) << x << "," << y;
        for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(probe.fragments[i].held, i < want) << x << "," << y << " #" << i;
        ++probed;
        deep += n > 4 ? 1 : 0;
      }
    EXPECT_GT(probed, 20u);
    EXPECT_GT(deep, 5u);  // lists long enough for a k-buffer to drop fragments
  }
}

TEST(ProbeGpu, HybridSplitPredictsWhatTheMethodDraws) {
  context();
  const SampleReference& ref = sampleReference("iso", kW, kH);
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  struct Case {
    const char* method;
    std::map<std::string, std::string> params;
  };
  // 0.2 MiB at 80×64 leaves the variable-k buffers about a slot and a half per pixel.
  for (const Case& c : {Case{"kplus-array", {{"k", "3"}, {"tail", "true"}}}, Case{"vkb", {{"budget_mib", "0.2"}}},
                        Case{"dkb", {{"budget_mib", "0.2"}}}}) {
    SCOPED_TRACE(c.method);
    RenderRequest req;
    req.method = c.method;
    req.operation = "hybrid";
    req.width = kW;
    req.height = kH;
    req.params = c.params;
    const RenderOutput out = gpu.render(ref.camera, req);
    std::size_t probed = 0, withTail = 0, costly = 0;
    for (int y = 2; y < kH; y += 5)
      for (int x = 3; x < kW; x += 6) {
        if (ref.oracle.isAmbiguous(x, y) || ref.oracle.count(x, y) == 0) continue;
        PixelProbe probe = probePixel(ref.scene, ref.camera, kW, kH, x, y);
        const CapturedLists lists = gpu.capture(ref.camera, req, 64, PixelRect{x, y, 1, 1});
        matchCapture(probe, {lists.pixel(x, y), std::min<std::size_t>(lists.count(x, y), 64)}, lists.count(x, y));
        ASSERT_EQ(probe.unmatched, 0u) << x << "," << y;
        splitHybrid(probe, ref.scene.background);
        const std::uint8_t* drawn = out.image.at(x, y);
        int fromDrawn = 0, fromExact = 0;
        for (int k = 0; k < 3; ++k) {
          const int hybrid = static_cast<int>(std::lround(std::clamp(probe.hybridColor[k], 0.0f, 1.0f) * 255.0f));
          const int exact = static_cast<int>(std::lround(std::clamp(probe.exactColor[k], 0.0f, 1.0f) * 255.0f));
          fromDrawn = std::max(fromDrawn, std::abs(hybrid - drawn[k]));
          fromExact = std::max(fromExact, std::abs(hybrid - exact));
        }
        EXPECT_LE(fromDrawn, 2) << x << "," << y;
        ++probed;
        withTail += probe.heldCount() < probe.fragments.size() ? 1 : 0;
        costly += fromExact > 2 ? 1 : 0;
      }
    EXPECT_GT(probed, 30u);
    EXPECT_GT(withTail, 12u);  // the tails are exercised
    EXPECT_GT(costly, 5u);     // and the split is not simply the exact colour
  }
}

}  // namespace
}  // namespace mfr::test
