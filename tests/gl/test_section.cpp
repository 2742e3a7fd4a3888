// Section planes on the GPU: the sample cut and capped against the oracle; a capped box against the
// box that already has that shape (a second geometry, no section involved); CSG on cut solids; and
// the volume cropped to the kept half-space like the CPU march. The cutting itself is checked
// against closed-form geometry in tests/unit/test_section.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"
#include "mfr/scene/section.hpp"

namespace mfr::test {
namespace {

TEST(SectionGpu, ExactMethodsMatchTheOracleOnTheCutSample) {
  context();
  Scene scene = makeSampleScene();
  const Camera camera = scene.view("iso");
  const int w = 96, h = 80;
  const FragmentLists whole = castFragments(scene, camera, w, h);
  scene.section = SectionPlane{scene.bounds().center() + glm::dvec3(0.1, 0.0, 0.0), {-1.0, 0.2, 0.3}, true};
  SectionReport report;
  (void)sectionedScene(scene, &report);
  EXPECT_GT(report.capped, 0u);  // the sample's closed parts are capped
  const FragmentLists cut = castFragments(scene, camera, w, h);
  std::size_t changed = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) changed += cut.count(x, y) != whole.count(x, y) ? 1 : 0;
  EXPECT_GT(changed, static_cast<std::size_t>(w * h / 10));
  for (const char* method : {"abuffer-ll", "kplus-array", "peel-dual"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.width = w;
    req.height = h;
    if (std::string(method) == "kplus-array") req.params["k"] = "64";
    if (std::string(method) == "peel-dual") req.params["max_passes"] = "64";
    const OracleMatch m = expectGpuMatchesOracle(scene, camera, req);
    EXPECT_GT(m.lists.compared, static_cast<std::size_t>(w * h / 2));
  }
}

Object boxObject(const glm::dvec3& size, const glm::dmat4& transform) {
  Object o;
  o.name = "box";
  o.mesh = std::make_shared<const Mesh>(makeBox(size));
  o.transform = transform;
  o.material.color = {0.2f, 0.6f, 0.9f, 0.6f};
  return o;
}

// A unit box cut at z = 0, keeping z <= 0, drawn by the GPU, equals the half box [-0.5, 0.5]² ×
// [-0.5, 0] drawn by the GPU: the cap is that box's top face.
TEST(SectionGpu, ACappedBoxLooksLikeTheBoxOfThatShape) {
  context();
  Camera camera;
  camera.eye = {0.9, 1.2, 2.5};
  camera.target = {0.0, 0.0, -0.2};
  const int w = 80, h = 64;
  Scene cut;
  cut.name = "cut";
  cut.objects.push_back(boxObject({1.0, 1.0, 1.0}, glm::dmat4(1.0)));
  cut.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, true};
  Scene half;
  half.name = "half";
  half.objects.push_back(boxObject({1.0, 1.0, 0.5}, glm::translate(glm::dmat4(1.0), {0.0, 0.0, -0.25})));
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = w;
  req.height = h;
  const ImageRGBA8 a = render(cut, camera, req).image;
  const ImageRGBA8 b = render(half, camera, req).image;
  const FragmentLists lists = castFragments(half, camera, w, h);
  const OffEdgeComparison c = compareOffEdges(lists, b, a, 2, [](int, int, int) {});
  EXPECT_GE(c.within, c.compared - c.compared / 1000) << c.within << " of " << c.compared;
  std::size_t covered = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) covered += lists.count(x, y) > 0 ? 1 : 0;
  EXPECT_GT(covered, static_cast<std::size_t>(w * h / 8));
  // Without caps the cut box is open: the inside shows through the top, unlike the half box.
  cut.section->caps = false;
  const ImageRGBA8 open = render(cut, camera, req).image;
  EXPECT_GT(maxRgbDifference(open, b), 20);
}

TEST(SectionGpu, CsgWorksOnCutSolids) {
  context();
  Scene scene = makeCsgSampleScene();
  const Camera camera = scene.view("fit");
  const int w = 80, h = 64;
  scene.section = SectionPlane{scene.bounds().center(), {0.3, -0.2, 1.0}, true};
  const FragmentLists lists = castFragments(scene, camera, w, h);
  const ImageRGBA8 expected = compositeCsg(lists, scene);
  RenderRequest req;
  req.method = "abuffer-ll";
  req.operation = "csg";
  req.width = w;
  req.height = h;
  const RenderOutput out = render(scene, camera, req);
  // Where the plane cuts overlapping solids their caps coincide (equal depths, the oracle flags the
  // pixel ambiguous) and the order of the tie decides the classification: those pixels are left out.
  std::size_t compared = 0, within = 0;
  (void)compareOffEdges(lists, expected, out.image, 2, [&](int x, int y, int d) {
    if (lists.isAmbiguous(x, y)) return;
    ++compared;
    within += d <= 2 ? 1 : 0;
  });
  EXPECT_GE(within, compared - compared / 1000) << within << " of " << compared;
  EXPECT_GT(compared, static_cast<std::size_t>(w * h / 2));
  scene.section.reset();
  const ImageRGBA8 uncut = compositeCsg(castFragments(scene, camera, w, h), scene);
  EXPECT_GT(maxRgbDifference(uncut, expected), 50);  // the cut shows
}

TEST(SectionGpu, VolumeIsCroppedToTheKeptSide) {
  context();
  Scene scene = makeVolumeSampleScene();
  const Camera camera = scene.view("iso");
  const int w = 128, h = 112;
  RenderRequest req;
  req.method = "abuffer-ll";
  req.operation = "volume";
  req.width = w;
  req.height = h;
  const ImageRGBA8 uncropped = render(scene, camera, req).image;
  scene.section = SectionPlane{scene.bounds().center(), {0.4, -1.0, 0.2}, true};
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  const Volume volume = scene.visibleVolumes().at(0);
  const ImageRGBA8 expected =
      compositeVolume(oracle, camera, volume, volume.defaultStep(), scene.background, scene.clipBox, scene.section);
  for (const char* method : {"abuffer-ll", "kplus-array"}) {
    SCOPED_TRACE(method);
    req.method = method;
    if (std::string(method) == "kplus-array") req.params["k"] = "32";
    const RenderOutput out = render(scene, camera, req);
    const OffEdgeComparison c = compareOffEdges(oracle, expected, out.image, 2, [](int, int, int) {});
    EXPECT_GE(c.within, c.compared - c.compared / 1000) << c.within << " of " << c.compared;
    EXPECT_GT(c.compared, static_cast<std::size_t>(w * h / 2));
    EXPECT_GT(pixelsDifferingBy(out.image, uncropped, 8), static_cast<std::size_t>(w * h / 20));  // measured 1,161
  }
}

}  // namespace
}  // namespace mfr::test
