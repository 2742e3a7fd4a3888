// Every exact method against the oracle: per-pixel fragment lists (counts, depths, colours) and
// final images, on the built-in sample and on real models. Methods instantiate these tests in
// their own files (test_<method>.cpp) with INSTANTIATE_TEST_SUITE_P(…, ExactMethod, …).
#include <gtest/gtest.h>

#include <filesystem>

#include "exact_method.hpp"
#include "gl_fixture.hpp"
#include "mfr/io/load.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

// The method's lists and image against the oracle (expectGpuMatchesOracle), nothing dropped.
void checkAgainstOracle(const Scene& scene, const Camera& camera, int w, int h, const ExactCase& c) {
  RenderRequest req;
  req.method = c.method;
  req.params = c.params;
  req.width = w;
  req.height = h;
  const OracleMatch m = expectGpuMatchesOracle(scene, camera, req);
  EXPECT_FALSE(m.out.stats.overflow);
  EXPECT_EQ(m.out.stats.fragmentsDropped, 0u);
  ::testing::Test::RecordProperty("ambiguous_pixels", static_cast<int>(m.lists.pixels - m.lists.compared));
  ::testing::Test::RecordProperty("pixels_off_by_more_than_2", static_cast<int>(m.image.compared - m.image.within));
}

TEST_P(ExactMethod, SampleMatchesOracle) {
  const Scene scene = makeSampleScene();
  checkAgainstOracle(scene, scene.view("front"), 160, 120, GetParam());
}

TEST_P(ExactMethod, SampleIsoViewMatchesOracle) {
  const Scene scene = makeSampleScene();
  checkAgainstOracle(scene, scene.view("iso"), 96, 96, GetParam());
}

// More fragments per pixel than the resolve's local array (64): the l+-depth-sorting rounds.
TEST_P(ExactMethod, DeepPixelsUseLPlusDepthSorting) {
  const Scene scene = makeQuadsScene(100, 0.5, 3);
  ExactCase c = GetParam();
  for (const auto& [k, v] : c.deepParams) c.params[k] = v;
  checkAgainstOracle(scene, scene.view("front"), 40, 32, c);
}

// Real CAD files (Debian packages occt-misc and assimp-testmodels, see shared/DATA.md).
TEST_P(ExactMethod, RealModelsMatchOracle) {
  for (const char* path : {"/usr/share/opencascade/data/stl/bearing.stl",
                           "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}) {
    SCOPED_TRACE(path);
    ASSERT_TRUE(std::filesystem::exists(path)) << "test data missing: run scripts/setup";
    Scene scene = loadScene(path);
    for (Object& o : scene.objects) o.material.color.a = 0.4f;  // see through the parts
    checkAgainstOracle(scene, scene.view("iso"), 128, 96, GetParam());
  }
}

}  // namespace
}  // namespace mfr::test
