#include "gl_fixture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>

#include "mfr/scene/sample.hpp"

namespace mfr::test {

gl::HeadlessContext& context() {
  static gl::HeadlessContext ctx(true);
  ctx.makeCurrent();
  return ctx;
}

int channelDiff(std::uint32_t a, std::uint32_t b) {
  int m = 0;
  for (int c = 0; c < 4; ++c)
    m = std::max(m, std::abs(static_cast<int>((a >> (8 * c)) & 0xFF) - static_cast<int>((b >> (8 * c)) & 0xFF)));
  return m;
}

ListComparison compareLists(const FragmentLists& oracle, const CapturedLists& gpu, std::uint32_t kNearest) {
  ListComparison r;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      ++r.pixels;
      if (oracle.isAmbiguous(x, y)) continue;
      ++r.compared;
      const auto exact = oracle.pixel(x, y);
      const std::uint32_t n = static_cast<std::uint32_t>(exact.size());
      const std::uint32_t expected = kNearest > 0 ? std::min(n, kNearest) : n;
      const std::uint32_t got = gpu.count(x, y);
      std::ostringstream why;
      if (got != expected) {
        ++r.countMismatches;
        why << "pixel (" << x << "," << y << "): count " << got << ", oracle " << expected;
      } else {
        const Fragment* f = gpu.pixel(x, y);
        const std::uint32_t m = std::min<std::uint32_t>(expected, static_cast<std::uint32_t>(gpu.maxPerPixel));
        bool depthBad = false, colorBad = false;
        for (std::uint32_t i = 0; i < m; ++i) {
          if (std::abs(static_cast<double>(f[i].depth) - exact[i].depth) > rasterDepthTolerance(exact[i])) {
            if (!depthBad)
              why << "pixel (" << x << "," << y << ") fragment " << i << ": depth " << f[i].depth << ", oracle "
                  << exact[i].depth;
            depthBad = true;
          } else if (channelDiff(f[i].color, exact[i].color) > 2) {
            if (!colorBad && !depthBad)
              why << "pixel (" << x << "," << y << ") fragment " << i << ": colour differs by "
                  << channelDiff(f[i].color, exact[i].color);
            colorBad = true;
          }
        }
        r.depthMismatches += depthBad;
        r.colorMismatches += colorBad;
      }
      if (r.firstMismatch.empty()) r.firstMismatch = why.str();
    }
  return r;
}

ImageComparison compareImages(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                              int tolerance) {
  ImageComparison r;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      if (oracle.isAmbiguous(x, y)) continue;
      ++r.compared;
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(expected.at(x, y)[c] - actual.at(x, y)[c]));
      r.maxDifference = std::max(r.maxDifference, d);
      if (d <= tolerance) ++r.within;
    }
  return r;
}

const SampleReference& sampleReference(const std::string& view, int w, int h) {
  static std::map<std::tuple<std::string, int, int>, std::unique_ptr<const SampleReference>> cache;
  std::unique_ptr<const SampleReference>& r = cache[{view, w, h}];
  if (!r) {
    auto made = std::make_unique<SampleReference>();
    made->scene = makeSampleScene();
    made->camera = made->scene.view(view);
    made->oracle = castFragments(made->scene, made->camera, w, h);
    made->image = compositeOver(made->oracle, made->scene.background);
    r = std::move(made);
  }
  return *r;
}

OracleMatch expectGpuMatchesOracle(const Scene& scene, const Camera& camera, const RenderRequest& req) {
  context();
  const FragmentLists oracle = castFragments(scene, camera, req.width, req.height);
  const ImageRGBA8 expected = compositeOver(oracle, scene.background);

  GpuRenderer gpu;
  gpu.setScene(scene);
  OracleMatch m;
  const int keep = static_cast<int>(std::max<std::uint32_t>(oracle.maxCount(), 1));
  const CapturedLists lists = gpu.capture(camera, req, keep);
  m.lists = compareLists(oracle, lists);
  EXPECT_GT(m.lists.compared, m.lists.pixels * 7 / 10) << "too many ambiguous pixels";
  EXPECT_EQ(m.lists.countMismatches, 0u) << m.lists.firstMismatch;
  EXPECT_EQ(m.lists.depthMismatches, 0u) << m.lists.firstMismatch;
  EXPECT_EQ(m.lists.colorMismatches, 0u) << m.lists.firstMismatch;

  m.out = gpu.render(camera, req);
  m.image = compareImages(oracle, expected, m.out.image, 2);
  EXPECT_GE(m.image.fraction(), 0.999) << (m.image.compared - m.image.within) << " of " << m.image.compared
                                       << " pixels differ by more than 2/255; max " << m.image.maxDifference;
  return m;
}

}  // namespace mfr::test
