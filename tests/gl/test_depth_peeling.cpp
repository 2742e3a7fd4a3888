// Depth peeling against the oracle: front-to-back (Everitt 2001) and dual (Bavoil & Myers 2008).
// Both are exact given enough passes; with too few they report overflow and composite the layers
// they peeled (the nearest ones, or the nearest and the farthest for dual peeling).
#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "exact_method.hpp"
#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/gl/gpu_scene.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {

// The sample reaches about 40 layers; the defaults (64 passes, 32 dual passes) cover it.
INSTANTIATE_TEST_SUITE_P(DepthPeeling, ExactMethod,
                         ::testing::Values(ExactCase{"peel-f2b", {}, "default", {{"max_passes", "128"}}},
                                           ExactCase{"peel-dual", {}, "default", {{"max_passes", "64"}}}),
                         exactCaseName);

namespace {

RenderRequest request(const std::string& method, int w, int h, std::map<std::string, std::string> params = {}) {
  RenderRequest req;
  req.method = method;
  req.width = w;
  req.height = h;
  req.params = std::move(params);
  return req;
}

// The oracle's lists keeping, per pixel, the `front` nearest and the `back` farthest fragments:
// what a peeling stopped by its pass limit holds.
FragmentLists keepEnds(const FragmentLists& oracle, std::uint32_t front, std::uint32_t back) {
  FragmentLists out = oracle;
  out.fragments.clear();
  out.offsets.assign(1, 0);
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      const auto list = oracle.pixel(x, y);
      const std::uint32_t n = static_cast<std::uint32_t>(list.size());
      for (std::uint32_t i = 0; i < n; ++i)
        if (i < front || i + back >= n) out.fragments.push_back(list[i]);
      out.offsets.push_back(static_cast<std::uint32_t>(out.fragments.size()));
    }
  return out;
}

std::uint32_t maxCount(const CapturedLists& lists) {
  return *std::max_element(lists.counts.begin(), lists.counts.end());
}

std::uint32_t maxUnambiguousCount(const FragmentLists& oracle) {
  std::uint32_t m = 0;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x)
      if (!oracle.isAmbiguous(x, y)) m = std::max(m, oracle.count(x, y));
  return m;
}

std::string note(const Stats& s, const std::string& key) {
  for (const auto& [k, v] : s.notes)
    if (k == key) return v;
  return {};
}

}  // namespace

// Pass counts: one geometry pass per layer plus the pass that finds nothing left (f2b); the
// initialisation pass plus one per two layers (dual, whose stop query is a full-screen pass).
TEST(DepthPeeling, PassCountFollowsDepthComplexity) {
  context();
  const Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const int w = 96, h = 96;
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  GpuRenderer gpu;
  gpu.setScene(scene);

  const RenderRequest f2b = request("peel-f2b", w, h);
  const std::uint32_t layers = maxCount(gpu.capture(camera, f2b, static_cast<int>(oracle.maxCount())));
  EXPECT_GE(layers, maxUnambiguousCount(oracle));
  EXPECT_LE(layers, oracle.maxCount());
  EXPECT_GT(layers, 20u);
  const Stats sf = gpu.render(camera, f2b).stats;
  EXPECT_EQ(sf.passes, layers + 2);  // the count pass, the layers, the pass that finds nothing
  EXPECT_EQ(note(sf, "layers peeled"), std::to_string(layers));
  EXPECT_FALSE(sf.overflow);

  const Stats sd = gpu.render(camera, request("peel-dual", w, h)).stats;
  EXPECT_EQ(sd.passes, 1 + (layers + 1) / 2);
  EXPECT_FALSE(sd.overflow);
  // Both peel every fragment once (no depth ties in the sample).
  EXPECT_EQ(sd.fragmentsGenerated, sf.fragmentsGenerated);
  EXPECT_EQ(sd.fragmentsStored, sf.fragmentsStored);
  ::testing::Test::RecordProperty("layers", static_cast<int>(layers));
  ::testing::Test::RecordProperty("oracle_max_count", static_cast<int>(oracle.maxCount()));
}

// Too few passes: overflow is reported with the exact number of dropped fragments and pixels, and
// the image is the composite of the layers peeled.
TEST(DepthPeeling, FrontToBackPassLimitOverflows) {
  context();
  const Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const int w = 96, h = 96;
  const std::uint32_t k = 4;
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  GpuRenderer gpu;
  gpu.setScene(scene);
  const CapturedLists full = gpu.capture(camera, request("peel-f2b", w, h), static_cast<int>(oracle.maxCount()));
  const Stats exact = gpu.render(camera, request("peel-f2b", w, h)).stats;
  std::uint64_t dropped = 0, pixels = 0;
  for (const std::uint32_t n : full.counts)
    if (n > k) {
      dropped += n - k;
      ++pixels;
    }
  ASSERT_GT(pixels, 0u);

  const RenderRequest limited = request("peel-f2b", w, h, {{"max_passes", std::to_string(k)}});
  const RenderOutput out = gpu.render(camera, limited);
  EXPECT_TRUE(out.stats.overflow);
  EXPECT_EQ(out.stats.passes, k + 2);  // the count pass, k layers, the overflow check
  EXPECT_EQ(out.stats.fragmentsDropped, dropped);
  EXPECT_EQ(out.stats.overflowPixels, pixels);
  EXPECT_EQ(out.stats.fragmentsGenerated, exact.fragmentsGenerated);
  EXPECT_EQ(out.stats.fragmentsStored + out.stats.fragmentsDropped, out.stats.fragmentsGenerated);

  const FragmentLists front = keepEnds(oracle, k, 0);
  const ImageComparison ic = compareImages(oracle, compositeOver(front, scene.background), out.image, 2);
  EXPECT_GE(ic.fraction(), 0.999) << ic.maxDifference;
  const ListComparison lc = compareLists(oracle, gpu.capture(camera, limited, static_cast<int>(k)), k);
  EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
  EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
  EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;
}

TEST(DepthPeeling, DualPassLimitOverflows) {
  context();
  const Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const int w = 96, h = 96;
  const std::uint32_t passes = 2;  // the 2 nearest and the 2 farthest layers
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  GpuRenderer gpu;
  gpu.setScene(scene);
  const CapturedLists full = gpu.capture(camera, request("peel-dual", w, h), static_cast<int>(oracle.maxCount()));
  std::uint64_t dropped = 0, pixels = 0;
  for (const std::uint32_t n : full.counts)
    if (n > 2 * passes) {
      dropped += n - 2 * passes;
      ++pixels;
    }
  ASSERT_GT(pixels, 0u);

  const RenderRequest limited = request("peel-dual", w, h, {{"max_passes", std::to_string(passes)}});
  const RenderOutput out = gpu.render(camera, limited);
  EXPECT_TRUE(out.stats.overflow);
  EXPECT_EQ(out.stats.passes, 1 + passes + 1);  // init, peels, the counting pass
  EXPECT_EQ(out.stats.fragmentsDropped, dropped);
  EXPECT_EQ(out.stats.overflowPixels, pixels);
  EXPECT_EQ(out.stats.fragmentsStored + out.stats.fragmentsDropped, out.stats.fragmentsGenerated);

  const FragmentLists ends = keepEnds(oracle, passes, passes);
  const ImageComparison ic = compareImages(oracle, compositeOver(ends, scene.background), out.image, 2);
  EXPECT_GE(ic.fraction(), 0.999) << ic.maxDifference;
  // The dump holds the peeled fragments in depth order: the nearest and the farthest ones.
  const CapturedLists lists = gpu.capture(camera, limited, static_cast<int>(2 * passes));
  const ListComparison lc = compareLists(ends, lists);
  EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
  EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
  EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;
}

// Depth ties: @intersect holds one surface twice, so many pixels have two fragments at one depth.
// Peeling composites one per depth; the stats count every fragment rasterised (as the A-buffer
// does), the composited ones (the distinct depths of each pixel's list), those beyond the pass
// limit, and note the rest as depth ties. Expected counts come from the linked-list A-buffer's lists.
TEST(DepthPeeling, DepthTiesAreCountedNotStored) {
  context();
  const Scene scene = makeIntersectingSampleScene();
  const Camera camera = scene.views.front().camera;
  const int w = 96, h = 72;
  GpuRenderer gpu;
  gpu.setScene(scene);
  const Stats all = gpu.render(camera, request("abuffer-ll", w, h)).stats;
  std::uint32_t deepest = 0;
  for (const std::uint32_t n : gpu.capture(camera, request("abuffer-ll", w, h), 1).counts)
    deepest = std::max(deepest, n);
  const CapturedLists lists = gpu.capture(camera, request("abuffer-ll", w, h), static_cast<int>(deepest));
  // Per pixel: the distinct depths, nearest first, and how many fragments lie at each.
  std::vector<std::vector<std::uint32_t>> perDepth;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::vector<float> depths;
      for (std::uint32_t i = 0; i < lists.count(x, y); ++i) depths.push_back(lists.pixel(x, y)[i].depth);
      std::sort(depths.begin(), depths.end());
      std::vector<std::uint32_t> runs;
      for (std::size_t i = 0; i < depths.size(); ++i)
        if (i > 0 && depths[i] == depths[i - 1])
          ++runs.back();
        else
          runs.push_back(1);
      perDepth.push_back(std::move(runs));
    }
  std::uint64_t ties = 0;
  for (const auto& runs : perDepth)
    for (const std::uint32_t r : runs) ties += r - 1;
  ASSERT_GT(ties, 100u);

  // Expected stats when peeling keeps `front` nearest and `back` farthest depths of each pixel.
  const auto expect = [&](const Stats& s, std::uint32_t front, std::uint32_t back) {
    std::uint64_t stored = 0, dropped = 0, tied = 0;
    for (const auto& runs : perDepth)
      for (std::size_t i = 0; i < runs.size(); ++i)
        if (i < front || i + back >= runs.size()) {
          ++stored;
          tied += runs[i] - 1;
        } else {
          dropped += runs[i];
        }
    EXPECT_EQ(s.fragmentsGenerated, all.fragmentsGenerated);
    EXPECT_EQ(s.fragmentsStored, stored);
    EXPECT_EQ(s.fragmentsDropped, dropped);
    EXPECT_EQ(s.overflow, dropped > 0);
    EXPECT_EQ(note(s, "depth ties").substr(0, note(s, "depth ties").find(' ')), std::to_string(tied));
  };
  const std::uint32_t unlimited = 1024;
  {
    SCOPED_TRACE("peel-f2b");
    expect(gpu.render(camera, request("peel-f2b", w, h)).stats, unlimited, 0);
  }
  {
    SCOPED_TRACE("peel-dual");
    expect(gpu.render(camera, request("peel-dual", w, h)).stats, unlimited, 0);
  }
  {
    SCOPED_TRACE("peel-f2b max_passes=2");
    expect(gpu.render(camera, request("peel-f2b", w, h, {{"max_passes", "2"}})).stats, 2, 0);
  }
  {
    SCOPED_TRACE("peel-dual max_passes=1");
    expect(gpu.render(camera, request("peel-dual", w, h, {{"max_passes", "1"}})).stats, 1, 1);
  }
}

// Memory: fixed bytes per pixel, whatever the depth complexity or the pass limit.
TEST(DepthPeeling, MemoryIsPerPixelOnly) {
  context();
  const Scene sample = makeSampleScene();
  Scene sphere;
  sphere.objects.push_back(
      Object{"sphere", std::make_shared<Mesh>(makeSphere(1.0)), glm::dmat4(1.0), Material{}, true});
  for (const char* method : {"peel-f2b", "peel-dual"}) {
    const std::uint64_t perPixel = std::string(method) == "peel-f2b" ? 36 : 64;
    for (const Scene* scene : std::initializer_list<const Scene*>{&sample, &sphere})
      for (const auto& [w, h] : {std::pair{64, 48}, std::pair{80, 80}})
        for (const char* passes : {"1", "8"}) {
          SCOPED_TRACE(std::string(method) + " " + scene->name + " " + std::to_string(w) + "x" + std::to_string(h) +
                       " max_passes=" + passes);
          GpuRenderer gpu;
          gpu.setScene(*scene);
          const Stats s = gpu.render(scene->view("fit"), request(method, w, h, {{"max_passes", passes}})).stats;
          EXPECT_EQ(s.bytesAllocated, perPixel * static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h));
          EXPECT_EQ(s.bytesUsed, s.bytesAllocated);
        }
  }
}

// A scene with a single convex closed surface has exactly two layers per covered pixel: f2b takes
// 3 passes, dual 2 (init + one peel), and neither overflows with the smallest useful limit.
TEST(DepthPeeling, SphereNeedsTwoLayers) {
  context();
  Scene sphere;
  sphere.objects.push_back(
      Object{"sphere", std::make_shared<Mesh>(makeSphere(1.0)), glm::dmat4(1.0), Material{}, true});
  GpuRenderer gpu;
  gpu.setScene(sphere);
  const Camera camera = sphere.view("fit");
  const Stats f2b = gpu.render(camera, request("peel-f2b", 64, 64, {{"max_passes", "2"}})).stats;
  EXPECT_EQ(f2b.passes, 4u);  // the count pass, 2 layers, the overflow check, which finds nothing
  EXPECT_FALSE(f2b.overflow);
  const Stats dual = gpu.render(camera, request("peel-dual", 64, 64, {{"max_passes", "1"}})).stats;
  EXPECT_EQ(dual.passes, 2u);
  EXPECT_FALSE(dual.overflow);
  EXPECT_EQ(dual.fragmentsStored, f2b.fragmentsStored);
  EXPECT_GT(f2b.fragmentsStored, 0u);
}

// Peeling keeps no lists: operations other than oit and dump are refused with a clear error.
TEST(DepthPeeling, UnsupportedOperationThrows) {
  context();
  const Scene scene = makeSampleScene();
  const gl::GpuScene gpuScene(scene);
  gl::PassTimer timer;
  const FrameContext ctx{gpuScene, gl::FrameUniforms{}, scene.background, 32, 32, timer};
  for (const char* name : {"peel-f2b", "peel-dual"}) {
    std::unique_ptr<Method> method = createMethod(name);
    method->configure(32, 32, Params(method->info().params, {}, name));
    method->capture(ctx);
    EXPECT_THROW(method->resolve(ctx, Operation{"csg", "ops/csg.glsl", nullptr}), Error) << name;
  }
}

TEST(DepthPeeling, RejectsBadPassLimit) {
  for (const char* name : {"peel-f2b", "peel-dual"}) {
    const std::unique_ptr<Method> method = createMethod(name);
    EXPECT_THROW(Params(method->info().params, {{"max_passes", "0"}}, name), Error);
    EXPECT_THROW(Params(method->info().params, {{"max_passes", "1025"}}, name), Error);
    EXPECT_THROW(Params(method->info().params, {{"max_passes", "2.5"}}, name), Error);
  }
}

}  // namespace mfr::test
