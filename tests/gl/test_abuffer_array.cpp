// abuffer-array (FreePipe, Liu et al. 2010; Crassin 2010) against the oracle: exact with enough
// slots (fixed and sized by a count pass); with too few slots, the dropped fragments and the
// overflowing pixels are counted exactly, each pixel keeps `slots` of its own fragments and the
// image stays the composite of what was kept; memory equals W·H·(4 + 8·slots) + 16.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "exact_method.hpp"
#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {

INSTANTIATE_TEST_SUITE_P(ABufferFixedArray, ExactMethod,
                         ::testing::Values(ExactCase{"abuffer-array", {{"slots", "64"}}, "slots64", {{"slots", "128"}}},
                                           ExactCase{"abuffer-array", {{"slots", "0"}}, "auto"}),
                         exactCaseName);

namespace {

// True when `kept` (sorted) is a sub-list of `all` (sorted): each kept fragment matches a distinct
// fragment of the pixel in depth (rasterDepthTolerance) and colour (2/255).
bool isSubList(const Fragment* kept, std::uint32_t n, std::span<const Fragment> all) {
  std::size_t j = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    while (j < all.size() &&
           !(std::abs(static_cast<double>(all[j].depth) - kept[i].depth) <= rasterDepthTolerance(all[j]) &&
             channelDiff(all[j].color, kept[i].color) <= 2))
      ++j;
    if (j == all.size()) return false;
    ++j;
  }
  return true;
}

// The captured lists as oracle-shaped lists, to composite them on the CPU.
FragmentLists asLists(const CapturedLists& c) {
  FragmentLists l;
  l.width = c.width;
  l.height = c.height;
  l.offsets.push_back(0);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const std::uint32_t n = std::min<std::uint32_t>(c.count(x, y), static_cast<std::uint32_t>(c.maxPerPixel));
      l.fragments.insert(l.fragments.end(), c.pixel(x, y), c.pixel(x, y) + n);
      l.offsets.push_back(static_cast<std::uint32_t>(l.fragments.size()));
    }
  l.flags.assign(static_cast<std::size_t>(c.width) * c.height, 0);
  return l;
}

}  // namespace

TEST(ABufferFixedArray, OverflowIsCountedAndKeepsSlotsOfEachPixel) {
  context();
  const Scene scene = makeSampleScene();
  const Camera cam = scene.view("front");
  const int w = 96, h = 96;
  const std::uint32_t slots = 4;
  const FragmentLists oracle = castFragments(scene, cam, w, h);
  ASSERT_GT(oracle.maxCount(), slots * 2) << "the sample must overflow 4 slots";

  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-array";
  req.width = w;
  req.height = h;
  req.params = {{"slots", std::to_string(slots)}};
  const RenderOutput out = gpu.render(cam, req);
  const CapturedLists lists = gpu.capture(cam, req, static_cast<int>(slots) + 1);

  // Oracle's view of the overflow, and how many pixels are ambiguous (edges, depth ties).
  std::uint64_t oracleTotal = 0, oracleOverflow = 0, oracleDropped = 0, ambiguous = 0, ambiguousFragments = 0;
  std::uint64_t keptTotal = 0, countBad = 0, subsetBad = 0;
  std::string firstBad;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint32_t n = oracle.count(x, y);
      oracleTotal += n;
      oracleOverflow += n > slots;
      oracleDropped += n > slots ? n - slots : 0;
      keptTotal += lists.count(x, y);
      EXPECT_LE(lists.count(x, y), slots) << "pixel holds more than its slots";
      if (oracle.isAmbiguous(x, y)) {
        ++ambiguous;
        ambiguousFragments += n + 2;  // an edge pixel may gain or lose a few fragments
        continue;
      }
      if (lists.count(x, y) != std::min(n, slots)) {
        if (firstBad.empty())
          firstBad = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): holds " +
                     std::to_string(lists.count(x, y)) + ", oracle " + std::to_string(n);
        ++countBad;
      } else if (!isSubList(lists.pixel(x, y), lists.count(x, y), oracle.pixel(x, y))) {
        if (firstBad.empty())
          firstBad = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): foreign fragment";
        ++subsetBad;
      }
    }
  EXPECT_EQ(countBad, 0u) << firstBad;
  EXPECT_EQ(subsetBad, 0u) << firstBad;

  const Stats& s = out.stats;
  EXPECT_TRUE(s.overflow);
  EXPECT_EQ(s.kMax, slots);
  EXPECT_EQ(s.fragmentsStored, keptTotal) << "stats disagree with what the resolve found";
  EXPECT_EQ(s.fragmentsDropped, s.fragmentsGenerated - s.fragmentsStored);
  const auto near = [&](std::uint64_t got, std::uint64_t want, std::uint64_t slack) {
    return got + slack >= want && got <= want + slack;
  };
  EXPECT_TRUE(near(s.fragmentsGenerated, oracleTotal, ambiguousFragments))
      << s.fragmentsGenerated << " generated, oracle " << oracleTotal << " ± " << ambiguousFragments;
  EXPECT_TRUE(near(s.fragmentsDropped, oracleDropped, ambiguousFragments))
      << s.fragmentsDropped << " dropped, oracle " << oracleDropped << " ± " << ambiguousFragments;
  EXPECT_TRUE(near(s.overflowPixels, oracleOverflow, ambiguous))
      << s.overflowPixels << " overflowing pixels, oracle " << oracleOverflow << " ± " << ambiguous;
  EXPECT_GT(s.overflowPixels, 0u);

  // The image is the composite of the kept fragments (never garbage). Which `slots` fragments an
  // overflowing pixel keeps depends on arrival order, identical between the two frames on llvmpipe
  // (a real GPU may differ on a few pixels).
  const ImageRGBA8 kept = compositeOver(asLists(lists), scene.background);
  std::size_t within = 0;
  int worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int d = 0;
      for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(kept.at(x, y)[c] - out.image.at(x, y)[c]));
      worst = std::max(worst, d);
      within += d <= 2;
    }
  EXPECT_GE(static_cast<double>(within) / (w * h), 0.99) << "max difference " << worst;
}

TEST(ABufferFixedArray, MemoryIsCounterPlusSlotsPerPixel) {
  context();
  const Scene scene = makeSampleScene();
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-array";
  for (const auto& [w, h, slots] : {std::tuple{64, 48, 1}, std::tuple{96, 80, 8}, std::tuple{40, 30, 100}}) {
    req.width = w;
    req.height = h;
    req.params = {{"slots", std::to_string(slots)}};
    const Stats s = gpu.render(scene.view("front"), req).stats;
    const std::uint64_t pixels = static_cast<std::uint64_t>(w) * h;
    EXPECT_EQ(s.bytesAllocated, pixels * (4 + 8 * static_cast<std::uint64_t>(slots)) + 16) << "slots " << slots;
    EXPECT_EQ(s.bytesUsed, pixels * 4 + s.fragmentsStored * 8 + 16);
    EXPECT_LE(s.bytesUsed, s.bytesAllocated);
    EXPECT_EQ(s.passes, 1u);
  }
}

// slots=0: a count pass sizes the arrays to the largest per-pixel count, so nothing overflows and
// the memory is W·H·(4 + 8·max count) + 16.
TEST(ABufferFixedArray, AutoSlotsFromCountPass) {
  context();
  const Scene scene = makeSampleScene();
  const Camera cam = scene.view("front");
  const int w = 80, h = 60;
  const FragmentLists oracle = castFragments(scene, cam, w, h);
  std::uint32_t maxUnambiguous = 0, maxAll = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      maxAll = std::max(maxAll, oracle.count(x, y));
      if (!oracle.isAmbiguous(x, y)) maxUnambiguous = std::max(maxUnambiguous, oracle.count(x, y));
    }
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-array";
  req.width = w;
  req.height = h;
  req.params = {{"slots", "0"}};
  const Stats s = gpu.render(cam, req).stats;
  EXPECT_FALSE(s.overflow);
  EXPECT_EQ(s.fragmentsDropped, 0u);
  EXPECT_EQ(s.overflowPixels, 0u);
  EXPECT_EQ(s.passes, 2u);
  EXPECT_GE(s.kMax, maxUnambiguous);
  EXPECT_LE(s.kMax, maxAll + 2);
  EXPECT_EQ(s.bytesAllocated, static_cast<std::uint64_t>(w) * h * (4 + 8 * static_cast<std::uint64_t>(s.kMax)) + 16);
}

TEST(ABufferFixedArray, RejectsSlotsOutOfRange) {
  context();
  const Scene scene = makeSampleScene();
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-array";
  req.width = 32;
  req.height = 32;
  req.params = {{"slots", "1025"}};
  EXPECT_THROW(gpu.render(scene.view("front"), req), Error);
  req.params = {{"slots", "-1"}};
  EXPECT_THROW(gpu.render(scene.view("front"), req), Error);
}

}  // namespace mfr::test
