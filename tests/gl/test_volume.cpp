// Operation "volume" on the GPU against the oracle: each method's sorted lists composited with the
// volume by shaders/ops/volume.glsl against compositeVolume on the oracle's exact lists (whose
// arithmetic tests/unit/test_volume.cpp checks against closed forms). Pixels on projected triangle
// edges are left out (rasterisation tie rules decide there); pixels the volume alone covers are
// compared too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "common/bindings.h"
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
      const ImageRGBA8 expected = compositeVolume(oracle, camera, scene.visibleVolumes(),
                                                  volumeStepOf(req, scene.visibleVolumes()), scene.background);
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
    const ImageRGBA8 expected = compositeVolume(oracle, camera, scene.visibleVolumes(),
                                                volumeStepOf(req, scene.visibleVolumes()), scene.background);
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

// The sample's field and its transfer points mapped by `map` must give the image of the unmapped
// ones, shaded and not, on both renderers (the GPU's volume operation and the oracle's march).
void expectMappedVolumeDrawsAsTheSample(const std::function<double(double)>& map) {
  for (const bool shaded : {false, true}) {
    SCOPED_TRACE(shaded ? "shaded" : "unshaded");
    Scene scene = makeVolumeSampleScene();
    scene.volumes[0].shading = shaded;
    Scene mapped = scene;
    Volume& volume = mapped.volumes[0];
    auto grid = std::make_shared<VolumeGrid>(*volume.grid);
    for (float& v : grid->values) v = static_cast<float>(map(v));
    volume.grid = grid;
    for (TransferPoint& p : volume.transfer.points) p.value = map(p.value);

    const int w = 96, h = 80;
    const Camera camera = scene.view("iso");
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    RenderRequest req;
    req.operation = "volume";
    req.width = w;
    req.height = h;
    req.method = "abuffer-ll";
    const double step = volumeStepOf(req, scene.visibleVolumes());
    const ImageRGBA8 expected = compositeVolume(oracle, camera, scene.visibleVolumes(), step, scene.background);
    const ImageRGBA8 oracleMapped = compositeVolume(oracle, camera, mapped.visibleVolumes(), step, mapped.background);
    GpuRenderer gpu;
    gpu.setScene(mapped);
    const ImageRGBA8 gpuMapped = gpu.render(camera, req).image;
    for (const ImageRGBA8* image : {&oracleMapped, &gpuMapped}) {
      const Comparison c = compareOffEdges(oracle, expected, *image, scene.background, 2);
      EXPECT_GT(c.volumeOnly, 100u);  // measured: 137
      EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
          << (image == &gpuMapped ? "gpu: " : "oracle: ") << c.compared - c.within
          << " pixels off by more than 2/255, max " << c.maxDifference;
    }
  }
}

// Values near ±FLT_MAX (a file's "no data" marks, or a field in large units): the transfer
// function's v − low and the gradient's differences overflow a float if taken as written (the
// oracle crashed on an infinite table index; the GPU drew no medium). The sample's field and its
// transfer points, mapped affinely onto [−3e38, 3e38].
TEST(VolumeGpu, ValuesNearFloatMaxRenderAsSmallOnes) {
  context();
  const glm::vec2 range = makeVolumeSampleScene().volumes[0].grid->range();
  const double mid = 0.5 * (static_cast<double>(range.x) + range.y);
  const double scale = 3e38 / (0.5 * (static_cast<double>(range.y) - range.x));
  const auto map = [&](double v) { return (v - mid) * scale; };
  ASSERT_GT(static_cast<float>(map(range.y)) - static_cast<double>(static_cast<float>(map(range.x))), 5e38);
  expectMappedVolumeDrawsAsTheSample(map);
}

// Values near the smallest floats: GPUs flush subnormals, and a volume whose values are about
// 1e-37 drew blank where the oracle drew it (a bug hunt: RMSE 0.25). The grid is uploaded scaled
// by a power of two and the transfer window with it (gl::uploadGrid). The sample's field and
// transfer points times 2^-120 (exact).
TEST(VolumeGpu, ValuesNearTheSmallestFloatsRenderAsOrdinaryOnes) {
  context();
  const glm::vec2 range = makeVolumeSampleScene().volumes[0].grid->range();
  const auto map = [](double v) { return v * std::ldexp(1.0, -120); };
  ASSERT_LT(std::max(std::abs(map(range.x)), std::abs(map(range.y))), 1e-35);
  expectMappedVolumeDrawsAsTheSample(map);
}

// A volume far from the origin keeps its detail: the march's positions are relative to the volumes'
// centre (volumeRaySetup). In world floats the sample's volume, moved by (1e7, −3e6, 2e6), drew
// another picture than at home (RMSE 0.17 at 1e7 for a small grid, a bug hunt), on both renderers
// alike, so only the picture at home tells. Surfaces and volume move together; orbit views fit.
TEST(VolumeGpu, FarFromTheOriginTheVolumeKeepsItsDetail) {
  context();
  const Scene home = makeVolumeSampleScene();
  Scene far = home;
  const glm::dmat4 move = glm::translate(glm::dmat4(1.0), glm::dvec3(1e7, -3e6, 2e6));
  for (Object& o : far.objects) o.transform = move * o.transform;
  for (Volume& v : far.volumes) v.transform = move * v.transform;
  const int w = 96, h = 80;
  RenderRequest req;
  req.method = "abuffer-ll";
  req.operation = "volume";
  req.width = w;
  req.height = h;
  GpuRenderer atHome, moved;
  atHome.setScene(home);
  moved.setScene(far);
  const Camera homeCamera = home.view("orbit:30:20"), farCamera = far.view("orbit:30:20");
  const ImageRGBA8 expected = atHome.render(homeCamera, req).image;
  const ImageRGBA8 gpu = moved.render(farCamera, req).image;
  const FragmentLists farLists = castFragments(far, farCamera, w, h);
  const ImageRGBA8 oracle = compositeVolume(farLists, farCamera, far.visibleVolumes(), 0.0, far.background);
  const Comparison g = compareOffEdges(farLists, expected, gpu, far.background, 2);
  const Comparison o = compareOffEdges(farLists, expected, oracle, far.background, 2);
  EXPECT_GT(g.volumeOnly, 100u);  // measured: 164
  EXPECT_GE(static_cast<double>(g.within) / g.compared, 0.999) << "GPU: max difference " << g.maxDifference;
  EXPECT_GE(static_cast<double>(o.within) / o.compared, 0.999) << "oracle: max difference " << o.maxDifference;
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
  const ImageRGBA8 expected = compositeVolume(empty, camera, scene.visibleVolumes(), 0.0, scene.background);
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

// Several volumes at once (the operation's multiple volumes, up to MFR_MAX_VOLUMES, so every
// texture unit pair): the sample's volume, a turned and moved copy with another transfer function,
// a smaller shaded copy, and a coarse grid of its own across them — on the GPU against the oracle,
// with the surfaces inside. Each added volume must change the image.
Scene severalVolumesScene(std::size_t count) {
  Scene scene = makeVolumeSampleScene();
  const Volume base = scene.volumes[0];
  Volume turned = base;
  turned.name = "turned";
  turned.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 0.2, -0.3)) *
                     glm::rotate(glm::dmat4(1.0), glm::radians(30.0), glm::dvec3(0.0, 1.0, 0.0));
  turned.transfer = transferPreset("fire", 0.1, 1.0, 0.3);
  Volume small = base;
  small.name = "small";
  small.transform =
      glm::translate(glm::dmat4(1.0), glm::dvec3(-0.4, 0.1, 0.3)) * glm::scale(glm::dmat4(1.0), glm::dvec3(0.6));
  small.transfer = transferPreset("cool-warm", 0.0, 1.0, 0.2);
  small.shading = true;
  Volume coarse;
  coarse.name = "coarse";
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = glm::ivec3(7, 5, 9);
  for (int k = 0; k < 9; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 7; ++i) grid->values.push_back(static_cast<float>((i + 2 * j + k) % 5) / 4.0f);
  coarse.grid = grid;
  coarse.origin = glm::dvec3(-1.3, -0.5, -0.9);
  coarse.spacing = glm::dvec3(0.3, 0.25, 0.2);
  coarse.transfer = transferPreset("grayscale", 0.0, 1.0, 1.5);
  const Volume extra[] = {turned, small, coarse};
  for (std::size_t i = 0; i + 1 < count && i < 3; ++i) scene.volumes.push_back(extra[i]);
  return scene;
}

TEST(VolumeGpu, SeveralVolumesEqualTheOracle) {
  context();
  const int w = 128, h = 112;
  ImageRGBA8 previous;
  for (const std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{4}}) {
    const Scene scene = severalVolumesScene(count);
    ASSERT_EQ(scene.visibleVolumes().size(), count);
    GpuRenderer gpu;
    gpu.setScene(scene);
    const Camera camera = scene.view("iso");
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    RenderRequest req;
    req.operation = "volume";
    req.width = w;
    req.height = h;
    const ImageRGBA8 expected = compositeVolume(oracle, camera, scene.visibleVolumes(),
                                                volumeStepOf(req, scene.visibleVolumes()), scene.background);
    for (const char* method : {"abuffer-ll", "abuffer-sbuffer"}) {
      SCOPED_TRACE(std::to_string(count) + " volumes, " + method);
      req.method = method;
      const RenderOutput out = gpu.render(camera, req);
      const Comparison c = compareOffEdges(oracle, expected, out.image, scene.background, 2);
      EXPECT_GT(c.compared, static_cast<std::size_t>(w * h) * 8 / 10);
      EXPECT_GE(static_cast<double>(c.within) / c.compared, 0.999)
          << c.compared - c.within << " pixels off by more than 2/255, max " << c.maxDifference;
      const auto note = std::find_if(out.stats.notes.begin(), out.stats.notes.end(),
                                     [](const auto& n) { return n.first == "volumes"; });
      ASSERT_NE(note, out.stats.notes.end());
      EXPECT_EQ(note->second, std::to_string(count));
      // The copies share the sample's grid: one texture for them (its bytes counted once), a
      // transfer table each.
      const auto bytes = std::find_if(out.stats.notes.begin(), out.stats.notes.end(),
                                      [](const auto& n) { return n.first == "volume (bytes)"; });
      ASSERT_NE(bytes, out.stats.notes.end());
      const std::size_t sampleGrid = scene.volumes[0].grid->values.size() * sizeof(float);
      const std::size_t grids = count < 4 ? sampleGrid : sampleGrid + 7 * 5 * 9 * sizeof(float);
      EXPECT_EQ(bytes->second, std::to_string(grids + count * MFR_VOLUME_TF_SIZE * 4 * sizeof(float)));
    }
    if (count > 1) {
      std::size_t changed = 0;
      for (std::size_t i = 0; i < expected.pixels.size(); ++i)
        changed += std::abs(int(expected.pixels[i]) - int(previous.pixels[i])) > 8;
      EXPECT_GT(changed, 300u) << "the added volumes left the image as it was";
    }
    previous = expected;
  }
  // One more than MFR_MAX_VOLUMES visible: refused with a reason, nothing drawn.
  Scene five = severalVolumesScene(4);
  five.volumes.push_back(five.volumes[0]);
  five.volumes.back().name = "fifth";
  GpuRenderer gpu;
  EXPECT_THROW(gpu.setScene(five), Error);
  five.volumes.back().visible = false;
  EXPECT_NO_THROW(gpu.setScene(five));
}

}  // namespace
}  // namespace mfr::test
