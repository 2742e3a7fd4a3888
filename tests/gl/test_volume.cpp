// Operation "volume" on the GPU against the oracle: each method's sorted lists composited with the
// volume by shaders/ops/volume.glsl against compositeVolume on the oracle's exact lists (whose
// arithmetic tests/unit/test_volume.cpp checks against closed forms). Pixels on projected triangle
// edges are left out (rasterisation tie rules decide there); pixels the volume alone covers are
// compared too.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

struct Comparison : OffEdgeComparison {
  std::size_t volumeOnly = 0;  // compared pixels no surface covers but the medium colours
};

Comparison compareOffEdges(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                           const glm::vec3& background, int tolerance) {
  Comparison c;
  const auto isBackground = [&](int x, int y) {
    return expected.at(x, y)[0] == std::lround(background.r * 255.0f) &&
           expected.at(x, y)[1] == std::lround(background.g * 255.0f) &&
           expected.at(x, y)[2] == std::lround(background.b * 255.0f);
  };
  static_cast<OffEdgeComparison&>(c) =
      test::compareOffEdges(oracle, expected, actual, tolerance, [&](int x, int y, int) {
        if (oracle.count(x, y) == 0 && !isBackground(x, y)) ++c.volumeOnly;
      });
  return c;
}

TEST(VolumeGpu, EqualsTheOracleWithSurfacesInsideTheVolume) {
  context();
  const Scene scene = makeVolumeSampleScene();
  const int w = 128, h = 112;
  GpuRenderer gpu;
  gpu.setScene(scene);
  for (const char* view : {"iso", "front"}) {
    const Camera camera = scene.view(view);
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    for (const double step : {0.0, 0.037}) {  // the default (half the grid spacing) and a coarser one
      RenderRequest req;
      req.operation = "volume";
      req.width = w;
      req.height = h;
      req.volumeStep = step;
      const ImageRGBA8 expected = compositeVolume(oracle, camera, *scene.visibleVolume(),
                                                  volumeStepOf(req, *scene.visibleVolume()), scene.background);
      for (const char* method : {"abuffer-ll", "abuffer-array", "abuffer-sbuffer", "kplus-array", "kbuffer"}) {
        SCOPED_TRACE(std::string(view) + " " + method + " step " + std::to_string(step));
        req.method = method;
        req.params.clear();
        if (std::string(method) == "kplus-array" || std::string(method) == "kbuffer")
          req.params["k"] = std::to_string(oracle.maxCount());
        const RenderOutput out = gpu.render(camera, req);
        EXPECT_EQ(out.stats.operation, "volume");
        const Comparison c = compareOffEdges(oracle, expected, out.image, scene.background, 2);
        EXPECT_GT(c.compared, static_cast<std::size_t>(w * h) * 8 / 10);
        EXPECT_GT(c.volumeOnly, 200u);  // the medium where no surface is (measured: 280 in the iso view)
        EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
            << c.compared - c.within << " pixels off by more than 2/255, max " << c.maxDifference;
      }
    }
  }
}

// A shaded volume (gradient lighting, the sample's own field has smooth boundaries) on the GPU
// against the oracle's shaded image; shading must change the image where the medium is.
TEST(VolumeGpu, ShadedEqualsTheOracle) {
  context();
  Scene scene = makeVolumeSampleScene();
  const Scene unshaded = scene;
  scene.volumes[0].shading = true;
  const int w = 128, h = 112;
  GpuRenderer gpu, plain;
  gpu.setScene(scene);
  plain.setScene(unshaded);
  for (const char* view : {"iso", "front"}) {
    const Camera camera = scene.view(view);
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    RenderRequest req;
    req.operation = "volume";
    req.width = w;
    req.height = h;
    const ImageRGBA8 expected = compositeVolume(oracle, camera, *scene.visibleVolume(),
                                                volumeStepOf(req, *scene.visibleVolume()), scene.background);
    for (const char* method : {"abuffer-ll", "abuffer-sbuffer"}) {
      SCOPED_TRACE(std::string(view) + " " + method);
      req.method = method;
      const RenderOutput out = gpu.render(camera, req);
      const Comparison c = compareOffEdges(oracle, expected, out.image, scene.background, 2);
      EXPECT_GT(c.compared, static_cast<std::size_t>(w * h) * 8 / 10);
      EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
          << c.compared - c.within << " pixels off by more than 2/255, max " << c.maxDifference;
      const auto note = std::find_if(out.stats.notes.begin(), out.stats.notes.end(),
                                     [](const auto& n) { return n.first == "volume shading"; });
      ASSERT_NE(note, out.stats.notes.end());
      EXPECT_EQ(note->second, "on");
      std::size_t changed = 0;
      test::compareOffEdges(oracle, plain.render(camera, req).image, out.image, 8,
                            [&](int, int, int diff) { changed += diff > 8; });
      EXPECT_GT(changed, c.volumeOnly / 2) << "shading left the medium's " << c.volumeOnly << " pixels unchanged";
    }
  }
}

// The medium changes the image: the same scene with "oit" differs from "volume" wherever the
// volume is, and a scene of the volume alone (no triangles) renders on both renderers alike.
TEST(VolumeGpu, VolumeAloneAndAutoOperation) {
  context();
  Scene scene = makeVolumeSampleScene();
  const Camera camera = scene.view("iso");
  const int w = 96, h = 80;
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = w;
  req.height = h;
  req.operation = "auto";  // a scene with a volume: "volume"
  const RenderOutput autoOut = gpu.render(camera, req);
  EXPECT_EQ(autoOut.stats.operation, "volume");
  req.operation = "oit";
  const RenderOutput oit = gpu.render(camera, req);
  int changed = 0;
  for (std::size_t i = 0; i < oit.image.pixels.size(); ++i)
    changed += std::abs(int(oit.image.pixels[i]) - int(autoOut.image.pixels[i])) > 10;
  EXPECT_GT(changed, 500);
  bool noted = false;
  for (const auto& [k, v] : oit.stats.notes)
    noted = noted || (k == "volume" && v.find("not drawn") != std::string::npos);
  EXPECT_TRUE(noted);
  // Peeling composites while it peels: auto stays "oit" there.
  req.method = "peel-f2b";
  req.operation = "auto";
  EXPECT_EQ(gpu.render(camera, req).stats.operation, "oit");
  req.operation = "volume";
  EXPECT_THROW(gpu.render(camera, req), Error);

  scene.objects.clear();
  GpuRenderer alone;
  alone.setScene(scene);
  req.method = "abuffer-sbuffer";
  req.operation = "volume";
  const RenderOutput out = alone.render(camera, req);
  const FragmentLists empty = castFragments(scene, camera, w, h);
  EXPECT_EQ(empty.fragments.size(), 0u);
  const ImageRGBA8 expected =
      compositeVolume(empty, camera, *scene.visibleVolume(), scene.visibleVolume()->defaultStep(), scene.background);
  const Comparison c = compareOffEdges(empty, expected, out.image, scene.background, 2);
  EXPECT_EQ(c.compared, static_cast<std::size_t>(w * h));
  EXPECT_GT(c.volumeOnly, 600u);  // measured: 824
  EXPECT_EQ(c.within, c.compared) << "max difference " << c.maxDifference;

  // No visible volume: the operation is refused with a reason.
  Scene none = makeIntersectingSampleScene();
  GpuRenderer plain;
  plain.setScene(none);
  EXPECT_THROW(plain.render(none.view("iso"), req), Error);
}

}  // namespace
}  // namespace mfr::test
