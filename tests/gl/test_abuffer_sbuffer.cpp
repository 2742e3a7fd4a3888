// abuffer-sbuffer (Vasilakis & Fudos 2012) against the oracle with each fragment-buffer sizing;
// a too-small buffer keeps exactly the pixel ranges that fit (contiguous layout in GL pixel order)
// and counts the rest; memory equals 8·(W·H+1) + 4·scan scratch + 8·capacity + 8.
#include <algorithm>

#include "exact_method.hpp"
#include "gl_fixture.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {

INSTANTIATE_TEST_SUITE_P(ABufferSBuffer, ExactMethod,
                         ::testing::Values(ExactCase{"abuffer-sbuffer", {}, "count"},
                                           ExactCase{
                                               "abuffer-sbuffer", {{"pool", "fixed"}, {"pool_mib", "16"}}, "fixed"}),
                         exactCaseName);

namespace {

// Scan-scratch uints for n elements, computed by hand for the sizes below (blocks of 1024):
// n ≤ 1024 → 1 (the total); 1024 < n ≤ 1024² → ⌈n/1024⌉ block totals + 1.
std::uint64_t scratchFor(std::uint64_t n) {
  return n <= 1024 ? 1 : (n + 1023) / 1024 + 1;
}

}  // namespace

TEST(ABufferSBuffer, MemoryIsTwoWordsPerPixelPlusEightPerFragment) {
  context();
  const Scene scene = makeSampleScene();
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-sbuffer";
  for (const auto& [w, h] : {std::pair{96, 96}, std::pair{31, 33}}) {
    req.width = w;
    req.height = h;
    const Stats s = gpu.render(scene.view("front"), req).stats;
    const std::uint64_t n = static_cast<std::uint64_t>(w) * h + 1;
    EXPECT_FALSE(s.overflow);
    EXPECT_GT(s.fragmentsGenerated, 0u);
    EXPECT_EQ(s.fragmentsStored, s.fragmentsGenerated);
    EXPECT_EQ(s.bytesAllocated, 8 * n + 4 * scratchFor(n) + 8 * s.fragmentsGenerated + 8) << w << "x" << h;
    EXPECT_EQ(s.bytesUsed, s.bytesAllocated);  // count sizing: exactly the fragments stored
    EXPECT_EQ(s.passes, 2u);
  }
  // 96×96: 9217 entries → 10 block totals + the total.
  EXPECT_EQ(scratchFor(96 * 96 + 1), 11u);
}

// A fixed buffer smaller than the frame's fragments: pixels are laid out in GL order (bottom row
// first); every pixel whose range fits is complete, the one straddling the end is cut, the rest
// are empty — compared pixel by pixel with the ranges computed from an exact capture.
TEST(ABufferSBuffer, FixedPoolOverflowKeepsTheRangesThatFit) {
  context();
  const Scene scene = makeSampleScene();
  const Camera cam = scene.view("front");
  const int w = 96, h = 96;
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-sbuffer";
  req.width = w;
  req.height = h;
  const Stats exactStats = gpu.render(cam, req).stats;
  const CapturedLists exact = gpu.capture(cam, req, 64);
  ASSERT_FALSE(exactStats.overflow);

  const std::uint64_t capacity = 1310;  // 0.01 MiB / 8 bytes
  req.params = {{"pool", "fixed"}, {"pool_mib", "0.01"}};
  const Stats s = gpu.render(cam, req).stats;
  const CapturedLists cut = gpu.capture(cam, req, 64);
  ASSERT_GT(exactStats.fragmentsGenerated, capacity);

  EXPECT_TRUE(s.overflow);
  EXPECT_EQ(s.fragmentsGenerated, exactStats.fragmentsGenerated);
  EXPECT_EQ(s.fragmentsStored, capacity);
  EXPECT_EQ(s.fragmentsDropped, s.fragmentsGenerated - capacity);
  EXPECT_EQ(s.bytesAllocated,
            8 * (static_cast<std::uint64_t>(w) * h + 1) + 4 * scratchFor(w * h + 1) + 8 * capacity + 8);

  std::uint64_t offset = 0, overflowPixels = 0, wrong = 0, fragmentsWrong = 0;
  std::string first;
  for (int glY = 0; glY < h; ++glY)
    for (int x = 0; x < w; ++x) {
      const int y = h - 1 - glY;  // image row of GL row glY
      const std::uint64_t n = exact.count(x, y);
      const std::uint64_t fits = offset >= capacity ? 0 : std::min(n, capacity - offset);
      overflowPixels += fits < n;
      if (cut.count(x, y) != fits) {
        if (first.empty())
          first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): holds " +
                  std::to_string(cut.count(x, y)) + ", expected " + std::to_string(fits) + " of " + std::to_string(n);
        ++wrong;
      } else if (fits == n) {
        // Depths only: fragments of equal depth may swap colours between frames.
        for (std::uint64_t i = 0; i < std::min<std::uint64_t>(n, 64); ++i)
          if (cut.pixel(x, y)[i].depth != exact.pixel(x, y)[i].depth) {
            ++fragmentsWrong;
            break;
          }
      }
      offset += n;
    }
  EXPECT_EQ(wrong, 0u) << first;
  EXPECT_EQ(fragmentsWrong, 0u);
  EXPECT_EQ(s.overflowPixels, overflowPixels);
}

// pool=previous: no read-back between scan and store; the first frame guesses 8 per pixel, later
// frames take last frame's total + 10 % + 1024.
TEST(ABufferSBuffer, PreviousFrameSizing) {
  context();
  const Scene scene = makeSampleScene();
  const Camera cam = scene.view("front");
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-sbuffer";
  req.width = 64;
  req.height = 64;
  const std::uint64_t n = 64 * 64 + 1, fixedBytes = 8 * n + 4 * scratchFor(n) + 8;
  req.params = {{"pool", "previous"}};
  const Stats first = gpu.render(cam, req).stats;
  EXPECT_EQ(first.bytesAllocated, fixedBytes + 8 * (64 * 64 * 8));
  const Stats second = gpu.render(cam, req).stats;
  EXPECT_FALSE(second.overflow);
  EXPECT_EQ(second.fragmentsGenerated, first.fragmentsGenerated);
  const std::uint64_t t = first.fragmentsGenerated;
  EXPECT_EQ(second.bytesAllocated, fixedBytes + 8 * (t + t / 10 + 1024));
}

}  // namespace mfr::test
