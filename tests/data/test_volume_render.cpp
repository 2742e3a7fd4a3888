// Operation "volume" on a real file: CGAL's demo CT volume skull_2.9.inr (64³ floats, anisotropic
// spacing) with the "bone" transfer function, a probe sphere inside it and a translucent plate
// cutting through it, rendered by GPU methods and by the oracle: they must agree as on the
// generated sample (tests/gl/test_volume.cpp), from a perspective and an orthographic view.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/scene_file.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

fs::path cgalImages() {
  const char* env = std::getenv("MFR_TESTDATA_DIR");
  const fs::path data = env != nullptr && *env != '\0' ? fs::path(env) : fs::path(MFR_FETCHED_DATA_DIR);
  return data / "cgal" / "data" / "images";
}

constexpr const char* kScene = R"({
  "background": [1, 1, 1],
  "objects": [
    { "name": "probe", "primitive": { "type": "sphere", "radius": 40 }, "color": [0.9, 0.2, 0.2, 0.6],
      "transform": { "translate": [124, 124, 160] } },
    { "name": "cut", "primitive": { "type": "box", "size": [300, 300, 4] }, "color": [0.3, 0.5, 0.9, 0.3],
      "transform": { "translate": [124, 124, 115] } }
  ],
  "volumes": [ { "file": "skull_2.9.inr", "transfer": { "preset": "bone", "unit_distance": 6 } } ],
  "views": [
    { "name": "oblique", "eye": [500, 350, 600], "target": [124, 124, 115], "fit": true },
    { "name": "side", "eye": [600, 124, 115], "target": [124, 124, 115], "projection": "orthographic",
      "height": 320 }
  ]
})";

TEST(VolumeRealFile, SkullWithSurfacesInsideOnGpuEqualsTheOracle) {
  context();
  const fs::path dir = cgalImages();
  ASSERT_TRUE(fs::exists(dir / "skull_2.9.inr")) << "missing " << dir << " (scripts/setup extracts it)";
  const Scene scene = parseSceneFile(kScene, dir, "skull test scene");
  ASSERT_EQ(scene.visibleVolumes().size(), 1u);
  const int w = 128, h = 112;
  GpuRenderer gpu;
  gpu.setScene(scene);
  for (const char* view : {"oblique", "side"}) {
    const Camera camera = scene.view(view);
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    RenderRequest req;
    req.operation = "volume";
    req.width = w;
    req.height = h;
    const ImageRGBA8 expected = compositeVolume(oracle, camera, scene.visibleVolumes(), 0.0, scene.background);
    for (const char* method : {"abuffer-ll", "abuffer-sbuffer"}) {
      SCOPED_TRACE(std::string(view) + " " + method);
      req.method = method;
      const ImageRGBA8 actual = gpu.render(camera, req).image;
      std::size_t medium = 0;
      // The bone's colour (white to warm) where no surface covers the pixel.
      const OffEdgeComparison c = compareOffEdges(oracle, expected, actual, 2, [&](int x, int y, int) {
        medium += oracle.count(x, y) == 0 && expected.at(x, y)[2] < 235;
      });
      const std::size_t compared = c.compared, within = c.within;
      const int maxDifference = c.maxDifference;
      EXPECT_GT(compared, static_cast<std::size_t>(w * h) * 9 / 10);
      EXPECT_GE(static_cast<double>(within) / compared, 0.999)
          << compared - within << " pixels off by more than 2/255, max " << maxDifference;
      if (std::string(view) == "side") {
        EXPECT_GT(medium, 200u);  // (the plate covers the skull in the oblique view)
      }
    }
  }
}

// Two volumes at once from a scene file: the skull as bone, and a second copy of the CT turned
// 90° and moved half a skull along x with a soft-tissue ramp, so that the two overlap in part —
// the GPU's mixed media against the oracle's, and the image differs from the bone alone.
constexpr const char* kTwoVolumes = R"({
  "background": [0, 0, 0],
  "objects": [
    { "name": "probe", "primitive": { "type": "sphere", "radius": 40 }, "color": [0.9, 0.2, 0.2, 0.6],
      "transform": { "translate": [124, 124, 160] } }
  ],
  "volumes": [
    { "name": "bone", "file": "skull_2.9.inr", "transfer": { "preset": "bone", "unit_distance": 6 } },
    { "name": "tissue", "file": "skull_2.9.inr",
      "transform": { "rotate": { "axis": [0, 0, 1], "degrees": 90 }, "translate": [370, 0, 0] },
      "transfer": { "points": [[0, 0, 0, 0, 0], [1, 0.2, 0.8, 0.3, 0.4], [6, 0.1, 0.4, 1, 0.9]],
                    "unit_distance": 10 } }
  ],
  "views": [ { "name": "oblique", "eye": [600, 350, 650], "target": [200, 124, 115], "fit": true } ]
})";

TEST(VolumeRealFile, TwoOverlappingCtVolumesOnGpuEqualTheOracle) {
  context();
  const fs::path dir = cgalImages();
  ASSERT_TRUE(fs::exists(dir / "skull_2.9.inr")) << "missing " << dir << " (scripts/setup extracts it)";
  const Scene scene = parseSceneFile(kTwoVolumes, dir, "two-volume test scene");
  ASSERT_EQ(scene.visibleVolumes().size(), 2u);
  // The boxes overlap: the second (turned about z and moved) starts inside the first along x.
  const Bounds a = scene.volumes[0].bounds(), b = scene.volumes[1].bounds();
  ASSERT_LT(b.min.x, a.max.x);
  ASSERT_GT(b.max.x, a.max.x);
  const int w = 128, h = 96;
  GpuRenderer gpu;
  gpu.setScene(scene);
  const Camera camera = scene.view("oblique");
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  RenderRequest req;
  req.operation = "volume";
  req.width = w;
  req.height = h;
  const ImageRGBA8 expected = compositeVolume(oracle, camera, scene.visibleVolumes(), 0.0, scene.background);
  const ImageRGBA8 boneAlone = compositeVolume(oracle, camera, scene.volumes[0], 0.0, scene.background);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < expected.pixels.size(); ++i)
    changed += std::abs(int(expected.pixels[i]) - int(boneAlone.pixels[i])) > 8;
  EXPECT_GT(changed, 1000u) << "the second volume left the image as it was";
  for (const char* method : {"abuffer-ll", "abuffer-sbuffer"}) {
    SCOPED_TRACE(method);
    req.method = method;
    const ImageRGBA8 actual = gpu.render(camera, req).image;
    const OffEdgeComparison c = compareOffEdges(oracle, expected, actual, 2, [](int, int, int) {});
    EXPECT_GT(c.compared, static_cast<std::size_t>(w * h) * 9 / 10);
    EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
        << c.compared - c.within << " pixels off by more than 2/255, max " << c.maxDifference;
  }
}

}  // namespace
}  // namespace mfr::test
