// Every exact method against the oracle: per-pixel fragment lists (counts, depths, colours) and
// final images, on the built-in sample and on analytic scenes.
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr {
namespace {

struct ExactCase {
  std::string method;
  std::map<std::string, std::string> params;
};

class ExactMethod : public ::testing::TestWithParam<ExactCase> {};

TEST_P(ExactMethod, SampleListsAndImageMatchOracle) {
  test::context();
  const Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const int w = 160, h = 120;
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  const ImageRGBA8 expected = compositeOver(oracle, scene.background);

  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = GetParam().method;
  req.params = GetParam().params;
  req.width = w;
  req.height = h;
  const CapturedLists lists = gpu.capture(camera, req, 96);
  const test::ListComparison lc = test::compareLists(oracle, lists);
  EXPECT_GT(lc.compared, lc.pixels * 8 / 10) << "too many ambiguous pixels";
  EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
  EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
  EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;

  const RenderOutput out = gpu.render(camera, req);
  const test::ImageComparison ic = test::compareImages(oracle, expected, out.image, 2);
  EXPECT_GE(ic.fraction(), 0.999) << "max channel difference " << ic.maxDifference;
  EXPECT_EQ(out.stats.fragmentsDropped, 0u);
  EXPECT_FALSE(out.stats.overflow);
}

INSTANTIATE_TEST_SUITE_P(Methods, ExactMethod,
                         ::testing::Values(ExactCase{"abuffer-ll", {}}),
                         [](const auto& param) {
                           std::string n = param.param.method;
                           for (char& c : n)
                             if (!isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

}  // namespace
}  // namespace mfr
