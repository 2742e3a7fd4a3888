// The clip box on the GPU (six clip distances in common/scene.vert, the volume march limited to
// the box) against the oracle, which clips by testing each hit point: the sample cut open, and
// the volume sample cropped. The oracle's own clipping is checked by hand in tests/unit/test_clip.cpp.
#include <gtest/gtest.h>

#include <string>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/error.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

// The part of b between fractions lo and hi of its extent on each axis.
Bounds part(const Bounds& b, const glm::dvec3& lo, const glm::dvec3& hi) {
  Bounds r;
  r.min = b.min + lo * (b.max - b.min);
  r.max = b.min + hi * (b.max - b.min);
  return r;
}

TEST(ClipGpu, ExactMethodsMatchTheOracleInsideTheBox) {
  context();
  Scene scene = makeSampleScene();
  const Camera camera = scene.view("iso");
  const int w = 96, h = 80;
  const FragmentLists whole = castFragments(scene, camera, w, h);
  scene.clipBox = part(scene.bounds(), {0.25, 0.0, 0.1}, {0.8, 0.6, 0.55});
  const FragmentLists clipped = castFragments(scene, camera, w, h);
  // The box cuts: many pixels lose fragments, some keep some.
  std::size_t fewer = 0, kept = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      fewer += clipped.count(x, y) < whole.count(x, y) ? 1 : 0;
      kept += clipped.count(x, y) > 0 ? 1 : 0;
    }
  EXPECT_GT(fewer, static_cast<std::size_t>(w * h / 4));
  EXPECT_GT(kept, static_cast<std::size_t>(w * h / 8));
  for (const char* method : {"abuffer-ll", "abuffer-sbuffer", "kplus-array"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.width = w;
    req.height = h;
    if (std::string(method) == "kplus-array") req.params["k"] = "64";  // deeper than any list: exact
    const OracleMatch m = expectGpuMatchesOracle(scene, camera, req);
    EXPECT_GT(m.lists.compared, static_cast<std::size_t>(w * h / 2));
  }
  // n(p) of the count pass sees the box too.
  GpuRenderer gpu;
  gpu.setScene(scene);
  const std::vector<std::uint32_t> n = gpu.depthComplexity(camera, w, h);
  std::size_t compared = 0, equal = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (clipped.isAmbiguous(x, y)) continue;
      ++compared;
      equal += n[clipped.index(x, y)] == clipped.count(x, y) ? 1 : 0;
    }
  EXPECT_EQ(equal, compared);
}

TEST(ClipGpu, PeelingAndApproximateMethodsAreCutToo) {
  context();
  Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const int w = 96, h = 80;
  scene.clipBox = part(scene.bounds(), {0.0, 0.3, 0.0}, {1.0, 0.7, 1.0});
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  const ImageRGBA8 expected = compositeOver(oracle, scene.background);
  for (const char* method : {"peel-f2b", "peel-dual"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.width = w;
    req.height = h;
    req.params["max_passes"] = "64";
    const RenderOutput out = render(scene, camera, req);
    const OffEdgeComparison c = compareOffEdges(oracle, expected, out.image, 2, [](int, int, int) {});
    EXPECT_GE(c.within, c.compared - c.compared / 1000) << c.within << " of " << c.compared;
  }
  // Weighted blended OIT is approximate, but what the box removes is gone from it as well: the
  // rows above and below the box show the background.
  RenderRequest req;
  req.method = "wboit";
  req.width = w;
  req.height = h;
  const RenderOutput out = render(scene, camera, req);
  for (int x = 0; x < w; ++x)
    for (const int y : {0, 2, h - 3, h - 1}) {
      if (oracle.count(x, y) != 0 || oracle.isAmbiguous(x, y)) continue;
      EXPECT_EQ(out.image.at(x, y)[0], expected.at(x, y)[0]) << x << "," << y;
    }
}

TEST(ClipGpu, VolumeIsCroppedLikeTheOracle) {
  context();
  Scene scene = makeVolumeSampleScene();
  const Camera camera = scene.view("iso");
  const int w = 128, h = 112;
  const ImageRGBA8 uncropped = render(scene, camera,
                                      [&] {
                                        RenderRequest r;
                                        r.method = "abuffer-ll";
                                        r.operation = "volume";
                                        r.width = w;
                                        r.height = h;
                                        return r;
                                      }())
                                   .image;
  scene.clipBox = part(scene.bounds(), {0.0, 0.0, 0.0}, {0.55, 1.0, 0.7});
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  const Volume volume = scene.visibleVolumes().at(0);
  const ImageRGBA8 expected =
      compositeVolume(oracle, camera, volume, volume.defaultStep(), scene.background, scene.clipBox);
  for (const char* method : {"abuffer-ll", "kplus-array"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.operation = "volume";
    req.width = w;
    req.height = h;
    if (std::string(method) == "kplus-array") req.params["k"] = "32";
    const RenderOutput out = render(scene, camera, req);
    const OffEdgeComparison c = compareOffEdges(oracle, expected, out.image, 2, [](int, int, int) {});
    EXPECT_GE(c.within, c.compared - c.compared / 1000) << c.within << " of " << c.compared;
    EXPECT_GT(c.compared, static_cast<std::size_t>(w * h / 2));
    // And the box changes the picture a lot: cropping is not a no-op.
    EXPECT_GT(pixelsDifferingBy(out.image, uncropped, 8), static_cast<std::size_t>(w * h / 10));
  }
}

TEST(ClipGpu, CsgRefusesAClipBox) {
  context();
  Scene scene = makeCsgSampleScene();
  scene.clipBox = scene.bounds();
  for (const char* method : {"abuffer-ll", "oracle"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.operation = "csg";
    req.width = 32;
    req.height = 32;
    try {
      (void)render(scene, scene.view("fit"), req);
      ADD_FAILURE() << "rendered";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("clip box"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mfr::test
