// Operation "zthickness" on the GPU against the oracle: the image of each method's sorted lists
// against compositeZThickness on the oracle's exact lists (whose arithmetic tests/unit/
// test_zthickness.cpp checks against closed forms and brute-force integration). Unlike "over",
// pixels with coincident fragments (a part loaded twice) are compared too: z-thickness blending
// does not depend on their order.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>

#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

struct TieComparison {
  std::size_t compared = 0, within = 0, ties = 0, tiesWithin = 0;
  int maxDifference = 0;
};

// Every pixel except those on a projected triangle edge (rasterisation tie rules decide there).
TieComparison compareOffEdges(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                              int tolerance) {
  TieComparison c;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      if (oracle.isEdge(x, y)) continue;
      int diff = 0;
      for (int ch = 0; ch < 3; ++ch)
        diff = std::max(diff, std::abs(int(expected.at(x, y)[ch]) - int(actual.at(x, y)[ch])));
      const bool tie = (oracle.flags[oracle.index(x, y)] & FragmentLists::kDepthTie) != 0;
      ++c.compared;
      c.ties += tie;
      c.maxDifference = std::max(c.maxDifference, diff);
      if (diff <= tolerance) {
        ++c.within;
        c.tiesWithin += tie;
      }
    }
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
  EXPECT_GT(maxDiff("oit"), 40);  // measured: the plate's colour flips between grey and green
  EXPECT_LE(maxDiff("zthickness"), 1);
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
  RenderRequest bad;
  bad.method = "abuffer-ll";
  bad.operation = "zthickness";
  bad.width = bad.height = 32;
  bad.thickness = -1.0;
  EXPECT_THROW((void)gpu.render(camera, bad), Error);
}

}  // namespace
}  // namespace mfr::test
