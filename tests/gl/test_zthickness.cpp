// Operation "zthickness" on the GPU against the oracle: the image of each method's sorted lists
// against compositeZThickness on the oracle's exact lists (whose arithmetic tests/unit/
// test_zthickness.cpp checks against closed forms and brute-force integration). Unlike "over",
// pixels with coincident fragments (a part loaded twice) are compared too: z-thickness blending
// does not depend on their order.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "common/bindings.h"
#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

struct TieComparison : OffEdgeComparison {
  std::size_t ties = 0, tiesWithin = 0;  // compared pixels with coincident fragments
};

TieComparison compareOffEdges(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                              int tolerance) {
  TieComparison c;
  static_cast<OffEdgeComparison&>(c) =
      test::compareOffEdges(oracle, expected, actual, tolerance, [&](int x, int y, int diff) {
        const bool tie = (oracle.flags[oracle.index(x, y)] & FragmentLists::kDepthTie) != 0;
        c.ties += tie;
        c.tiesWithin += tie && diff <= tolerance;
      });
  return c;
}

TEST(ZThicknessGpu, EqualsTheOracleOnIntersectingAndCoincidentSurfaces) {
  context();
  const Scene scene = makeIntersectingSampleScene();
  const int w = 128, h = 112;
  GpuRenderer gpu;
  gpu.setScene(scene);
  for (const char* view : {"iso", "front"}) {
    const Camera camera = scene.view(view);
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    for (const double thickness : {0.0, 0.15}) {  // the default (1 % of the diagonal) and a thick one
      RenderRequest req;
      req.operation = "zthickness";
      req.width = w;
      req.height = h;
      req.thickness = thickness;
      const ImageRGBA8 expected =
          compositeZThickness(oracle, camera, zThicknessOf(req, scene.bounds()), scene.background);
      for (const char* method : {"abuffer-ll", "abuffer-array", "abuffer-sbuffer", "kplus-array"}) {
        SCOPED_TRACE(std::string(view) + " " + method + " thickness " + std::to_string(thickness));
        req.method = method;
        req.params.clear();
        if (std::string(method) == "kplus-array") req.params["k"] = std::to_string(oracle.maxCount());
        const RenderOutput out = gpu.render(camera, req);
        const TieComparison c = compareOffEdges(oracle, expected, out.image, 2);
        EXPECT_GT(c.compared, static_cast<std::size_t>(w * h) * 8 / 10);
        EXPECT_GT(c.ties, 400u);  // the doubled plate: coincident fragments, compared as well
        EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
            << c.compared - c.within << " pixels off by more than 2/255, max " << c.maxDifference;
        EXPECT_EQ(c.tiesWithin, c.ties);
      }
    }
  }
}

// A part loaded twice: "over" shows whichever copy was drawn first (z-fighting); z-thickness
// blends the two the same way in either draw order.
TEST(ZThicknessGpu, CoincidentPartsLookTheSameInEitherDrawOrder) {
  context();
  const Scene scene = makeIntersectingSampleScene();
  Scene swapped = scene;
  const auto plate =
      std::find_if(swapped.objects.begin(), swapped.objects.end(), [](const Object& o) { return o.name == "plate"; });
  ASSERT_NE(plate, swapped.objects.end());
  std::iter_swap(plate, plate + 1);
  const Camera camera = scene.view("iso");
  const int w = 128, h = 112;
  GpuRenderer a, b;
  a.setScene(scene);
  b.setScene(swapped);
  const auto maxDiff = [&](const std::string& op) {
    RenderRequest req;
    req.method = "abuffer-ll";
    req.operation = op;
    req.width = w;
    req.height = h;
    const ImageRGBA8 x = a.render(camera, req).image, y = b.render(camera, req).image;
    int m = 0;
    for (int py = 0; py < h; ++py)
      for (int px = 0; px < w; ++px)
        for (int ch = 0; ch < 3; ++ch) m = std::max(m, std::abs(int(x.at(px, py)[ch]) - int(y.at(px, py)[ch])));
    return m;
  };
  EXPECT_GT(maxDiff("oit"), 20);  // measured 40: the plate's colour flips between grey and green
  EXPECT_LE(maxDiff("zthickness"), 1);
}

// kbuffer-zmerge with a slot for every fragment merges nothing: its own resolve of the stored
// segments must then give the operation's image (the oracle's), coincident faces included. Also
// with the scene scaled by 1e7, whose default slab (1 % of the diagonal) is longer than a half
// float holds: the segments kept their lengths in scene units, and the image came out blank.
TEST(ZThicknessMergeKBuffer, WithRoomForEveryFragmentEqualsTheOracle) {
  context();
  const int w = 128, h = 112;
  for (const auto& [scale, view] : {std::pair{1.0, "iso"}, std::pair{1.0, "front"}, std::pair{1e7, "iso"}}) {
    SCOPED_TRACE(std::string(view) + " scale " + std::to_string(scale));
    Scene scene = makeIntersectingSampleScene();
    for (Object& o : scene.objects) o.transform = glm::scale(glm::dmat4(1.0), glm::dvec3(scale)) * o.transform;
    GpuRenderer gpu;
    gpu.setScene(scene);
    const Camera camera = scene.fit(scene.view(view));  // the view's direction, framing the scaled scene too
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    ASSERT_LE(oracle.maxCount(), static_cast<std::uint32_t>(MFR_ZMERGE_MAX_K));
    RenderRequest req;
    req.method = "kbuffer-zmerge";
    req.operation = "auto";
    req.width = w;
    req.height = h;
    req.params["k"] = std::to_string(oracle.maxCount());
    const RenderOutput out = gpu.render(camera, req);
    EXPECT_EQ(out.stats.operation, "zthickness");
    const auto merges =
        std::find_if(out.stats.notes.begin(), out.stats.notes.end(), [](const auto& n) { return n.first == "merges"; });
    ASSERT_NE(merges, out.stats.notes.end());
    EXPECT_EQ(merges->second, "0");
    const ImageRGBA8 expected =
        compositeZThickness(oracle, camera, zThicknessOf(req, scene.bounds()), scene.background);
    const TieComparison c = compareOffEdges(oracle, expected, out.image, 2);
    EXPECT_GT(c.ties, 400u);
    EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
        << c.compared - c.within << " pixels off by more than 2/255, max " << c.maxDifference;
    EXPECT_EQ(c.tiesWithin, c.ties);
  }
}

// Merging keeps every pixel's opacity: a merged segment's optical depth is the sum of its parts',
// so the transmittance Π(1 - α_i) of all the pixel's fragments (α clamped as the operation does)
// survives any number of merges, while a k-buffer that drops fragments loses it. Measured through
// the image: with every part black (shading keeps black black), a pixel over a white background
// is the transmittance itself. (Black parts make the merged colour 0 whatever order the fragments
// arrive in: with coloured parts, the colour's 8-bit rounding at each merge depends on the
// order, which a GPU changes from frame to frame.)
TEST(ZThicknessMergeKBuffer, MergingKeepsEveryPixelsOpacity) {
  context();
  const int w = 128, h = 128;
  Scene white = sampleReference("front", w, h).scene;
  white.background = glm::vec3(1.0f);
  for (Object& o : white.objects) {
    o.material.color = glm::vec4(0.0f, 0.0f, 0.0f, o.material.color.a);
    o.material.vertexColors = false;
    o.material.fieldColors.reset();
  }
  const Camera camera = white.view("front");
  const FragmentLists& oracle = sampleReference("front", w, h).oracle;  // the same geometry and opacities
  GpuRenderer onWhite;
  onWhite.setScene(white);
  std::string firstWrong;
  const auto wrongPixels = [&](const RenderRequest& req, std::size_t& deep) {
    const RenderOutput out = onWhite.render(camera, req);
    std::size_t wrong = 0;
    deep = 0;
    firstWrong = "lock failures " + std::to_string(out.stats.lockFailures);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (oracle.isEdge(x, y)) continue;
        double transmittance = 1.0;
        for (const Fragment& f : oracle.pixel(x, y))
          transmittance *= 1.0 - std::min<double>((f.color >> 24) / 255.0, MFR_ZTHICK_MAX_ALPHA);
        deep += oracle.count(x, y) > 4u;
        for (int ch = 0; ch < 3; ++ch) {
          const int measured = out.image.at(x, y)[ch];
          if (std::abs(measured - transmittance * 255.0) > 1.5) {
            if (++wrong == 1)
              firstWrong += "; pixel (" + std::to_string(x) + "," + std::to_string(y) + ") of " +
                            std::to_string(oracle.count(x, y)) + " fragments: transmittance " +
                            std::to_string(measured / 255.0) + ", oracle " + std::to_string(transmittance);
            break;
          }
        }
      }
    return wrong;
  };
  for (const char* k : {"1", "2", "4"}) {
    SCOPED_TRACE(std::string("k = ") + k);
    RenderRequest merge;
    merge.method = "kbuffer-zmerge";
    merge.operation = "zthickness";
    merge.width = w;
    merge.height = h;
    merge.params["k"] = k;
    std::size_t deep = 0;
    EXPECT_EQ(wrongPixels(merge, deep), 0u) << firstWrong;
    EXPECT_GT(deep, 2000u);  // pixels with more fragments than slots: merging happened there
    // The k nearest alone (kplus-array) lose the rest's opacity: the check can fail.
    RenderRequest drop = merge;
    drop.method = "kplus-array";
    EXPECT_GT(wrongPixels(drop, deep), 1000u);
  }
}

TEST(ZThicknessGpu, MethodsWithoutSortedListsRefuseIt) {
  context();
  GpuRenderer gpu;
  gpu.setScene(makeIntersectingSampleScene());
  const Camera camera = makeIntersectingSampleScene().view("iso");
  for (const char* method : {"peel-f2b", "peel-dual", "wboit", "mboit"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.operation = "zthickness";
    req.width = 32;
    req.height = 32;
    EXPECT_THROW((void)gpu.render(camera, req), Error);
  }
  // kbuffer-zmerge keeps segments, not fragments: every other operation is refused.
  for (const char* op : {"oit", "hybrid", "csg"}) {
    SCOPED_TRACE(op);
    RenderRequest req;
    req.method = "kbuffer-zmerge";
    req.operation = op;
    req.width = 32;
    req.height = 32;
    EXPECT_THROW((void)gpu.render(camera, req), Error);
  }
  RenderRequest bad;
  bad.method = "abuffer-ll";
  bad.operation = "zthickness";
  bad.width = bad.height = 32;
  bad.thickness = -1.0;
  EXPECT_THROW((void)gpu.render(camera, bad), Error);
}

}  // namespace
}  // namespace mfr::test
