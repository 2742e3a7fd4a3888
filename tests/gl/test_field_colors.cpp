// Surfaces coloured by a field on the GPU (common/color_map.glsl: the value interpolated across the
// triangle, then mapped through the map's table) against the oracle, which interpolates at the ray's
// hit and maps with mfr::mapFieldValue: point data and cell data, several maps, through the exact
// methods, a k-buffer and depth peeling, and on a sectioned scene whose caps carry the field. A
// surface coloured by a volume ("@NAME") takes the volume's value at each of its points instead.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/reference/probe.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/section.hpp"

namespace mfr::test {
namespace {

// A sphere with point data "height" (its z, from -1 to 1) and "swirl" (a vector whose magnitude
// varies around it), and a torus around it with cell data "cell" (the triangle's index mod 7).
Scene fieldScene() {
  Scene scene;
  scene.name = "fields";
  auto sphere = std::make_shared<Mesh>(makeSphere(1.0, 40, 20));
  MeshField height{"height", false, 1, {}}, swirl{"swirl", false, 3, {}};
  for (const glm::vec3& p : sphere->positions) {
    height.values.push_back(p.z);
    swirl.values.insert(swirl.values.end(), {p.x * 2.0f, p.y, 0.5f});
  }
  sphere->fields = {height, swirl};
  auto torus = std::make_shared<Mesh>(makeTorus(1.6, 0.35, 48, 16));
  MeshField cell{"cell", true, 1, {}};
  for (std::size_t t = 0; t < torus->triangleCount(); ++t) cell.values.push_back(static_cast<float>(t % 7));
  torus->fields = {cell};
  Object a, b;
  a.name = "sphere";
  a.mesh = sphere;
  a.material.color = {0.8f, 0.8f, 0.8f, 0.5f};
  b.name = "torus";
  b.mesh = torus;
  b.transform = glm::rotate(glm::dmat4(1.0), 0.6, glm::dvec3(1.0, 0.0, 0.0));
  b.material.color = {0.8f, 0.8f, 0.8f, 0.6f};
  scene.objects = {a, b};
  return scene;
}

Camera view() {
  Camera c;
  c.eye = {2.5, 3.0, 4.5};
  c.target = {0.0, 0.0, 0.0};
  return c;
}

TEST(FieldColorsGpu, ExactMethodsMatchTheOracleWithPointAndCellData) {
  context();
  Scene scene = fieldScene();
  colorByField(scene.objects[0], "height", "cool-warm");
  colorByField(scene.objects[1], "cell", "viridis");
  const Camera camera = scene.fit(view());
  const int w = 96, h = 80;
  for (const char* method : {"abuffer-ll", "abuffer-sbuffer", "kplus-array", "peel-f2b"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.width = w;
    req.height = h;
    if (std::string(method) == "kplus-array") req.params["k"] = "16";
    if (std::string(method) == "peel-f2b") req.params["max_passes"] = "16";
    const OracleMatch m = expectGpuMatchesOracle(scene, camera, req);
    EXPECT_GT(m.lists.compared, static_cast<std::size_t>(w * h / 2));
  }
}

TEST(FieldColorsGpu, TheMapAndRangeChangeTheImageAndAreDrawnAsTheOracleDraws) {
  context();
  const Scene plain = fieldScene();
  const Camera camera = plain.fit(view());
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = 96;
  req.height = 80;
  const ImageRGBA8 before = render(plain, camera, req).image;
  ImageRGBA8 previous = before;
  for (const char* map : {"magma", "rainbow", "grayscale"}) {
    SCOPED_TRACE(map);
    Scene scene = plain;
    colorByField(scene.objects[0], "swirl:magnitude", map, glm::dvec2(0.5, 1.5));
    colorByField(scene.objects[1], "cell", map);
    const ImageRGBA8 image = render(scene, camera, req).image;
    // Every map shows: thousands of pixels change from the parts' grey and from the last map.
    EXPECT_GT(pixelsDifferingBy(before, image, 8), 2000u);
    EXPECT_GT(pixelsDifferingBy(previous, image, 8), 1000u);
    previous = image;
    RenderRequest oracle = req;
    oracle.method = "oracle";
    const ImageRGBA8 expected = render(scene, camera, oracle).image;
    const FragmentLists lists = castFragments(scene, camera, req.width, req.height);
    const OffEdgeComparison c = compareOffEdges(lists, expected, image, 2, [](int, int, int) {});
    EXPECT_GT(c.compared, 5000u);
    EXPECT_GE(c.within, c.compared * 999 / 1000) << "max difference " << c.maxDifference;
  }
}

TEST(FieldColorsGpu, SectionCapsCarryTheField) {
  context();
  Scene scene = fieldScene();
  scene.objects.resize(1);  // the sphere: closed, so it gets a cap
  scene.objects[0].material.color.a = 1.0f;
  colorByField(scene.objects[0], "swirl:0", "rainbow");
  scene.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, true};
  SectionReport report;
  const Scene cut = sectionedScene(scene, &report);
  ASSERT_EQ(report.capped, 1u);
  Camera camera;
  camera.eye = {0.0, 0.0, 4.0};  // looking at the cap, from the cut side
  camera = cut.fit(camera);
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = 80;
  req.height = 80;
  const OracleMatch m = expectGpuMatchesOracle(cut, camera, req);
  EXPECT_GT(m.lists.compared, 3000u);
  // The cap shows the field: x · 2 from −2 (blue) on the left to 2 (red) on the right.
  const ImageRGBA8& image = m.out.image;
  const std::uint8_t* left = image.at(22, 40);
  const std::uint8_t* right = image.at(58, 40);
  EXPECT_GT(left[2], left[0]);
  EXPECT_GT(right[0], right[2]);
}

TEST(FieldColorsGpu, NaNAndInfiniteValuesAreDrawnAsTheOracleDrawsThem) {
  // Some values missing (NaN: the map's NaN colour on every triangle touching them) and some out
  // of any range (±infinity: the map's ends).
  context();
  Scene scene = fieldScene();
  auto sphere = std::make_shared<Mesh>(*scene.objects[0].mesh);
  for (std::size_t v = 0; v < sphere->positions.size(); ++v) {
    float& h = sphere->fields[0].values[v];
    if (v % 17 == 3) h = std::numeric_limits<float>::quiet_NaN();
    if (v % 23 == 5) h = (v % 2 == 0 ? 1.0f : -1.0f) * std::numeric_limits<float>::infinity();
  }
  scene.objects[0].mesh = sphere;
  scene.objects.resize(1);
  colorByField(scene.objects[0], "height", "viridis");
  EXPECT_EQ(scene.objects[0].material.fieldColors->range, glm::dvec2(-1.0, 1.0));  // the finite values' range
  const Camera camera = scene.fit(view());
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = 80;
  req.height = 80;
  const OracleMatch m = expectGpuMatchesOracle(scene, camera, req);
  EXPECT_GT(m.lists.compared, 2000u);
  // The NaN colour (red for viridis) shows.
  std::size_t red = 0;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 80; ++x) {
      const std::uint8_t* p = m.out.image.at(x, y);
      red += p[0] > 200 && p[1] < 140 && p[2] < 140 ? 1 : 0;
    }
  EXPECT_GT(red, 50u);
}

// A volume "xy" whose value is x·y (bilinear, so trilinear interpolation of its samples gives
// exactly x·y at every point) over [-2, 2]² × [-1.5, 1.5].
Volume xyVolume() {
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = {9, 9, 7};
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i) grid->values.push_back(static_cast<float>((-2.0 + 0.5 * i) * (-2.0 + 0.5 * j)));
  Volume volume;
  volume.name = "xy";
  volume.grid = grid;
  volume.origin = {-2.0, -2.0, -1.5};
  volume.spacing = {0.5, 0.5, 0.5};
  volume.transfer = defaultTransfer(*grid, volume.bounds());
  volume.visible = false;  // only a field here
  return volume;
}

// The square [-1.5, 1.5]² at z = 0 facing +z, opaque, as cells × cells quads.
std::shared_ptr<Mesh> squareMesh(int cells) {
  auto m = std::make_shared<Mesh>();
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      m->positions.emplace_back(-1.5f + 3.0f * static_cast<float>(i) / static_cast<float>(cells),
                                -1.5f + 3.0f * static_cast<float>(j) / static_cast<float>(cells), 0.0f);
      m->normals.emplace_back(0.0f, 0.0f, 1.0f);
    }
  const auto at = [cells](int i, int j) { return static_cast<std::uint32_t>(j * (cells + 1) + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i)
      m->indices.insert(m->indices.end(),
                        {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

// Two triangles coloured by the volume x·y show x·y at every pixel — the same image, within 2/255,
// as a 120 × 120 grid of the square carrying x·y at its vertices (interpolated there, off by at most
// 6·10⁻⁵ of the range) — where interpolating the four corners' values (±2.25) would draw a
// different picture; on the GPU as in the oracle, through an A-buffer and a k-buffer.
TEST(FieldColorsGpu, VolumeColoursAreSampledAtEachPointNotInterpolated) {
  context();
  Scene coarse;
  coarse.name = "coarse";
  coarse.volumes = {xyVolume()};
  Object square;
  square.name = "square";
  square.mesh = squareMesh(1);
  coarse.objects = {square};
  addVolumeFields(coarse);
  colorByField(coarse.objects[0], "@xy", "grayscale", glm::dvec2(-2.25, 2.25));

  Scene fine;
  fine.name = "fine";
  Object reference = square;
  auto grid = squareMesh(120);
  MeshField xy{"xy", false, 1, {}};
  for (const glm::vec3& p : grid->positions) xy.values.push_back(p.x * p.y);
  grid->fields = {xy};
  reference.mesh = grid;
  fine.objects = {reference};
  colorByField(fine.objects[0], "xy", "grayscale", glm::dvec2(-2.25, 2.25));

  Camera camera;
  camera.eye = {0.6, -0.8, 5.0};  // a little oblique: the fragments' points are perspective-correct
  camera.target = {0.0, 0.0, 0.0};
  camera = coarse.fit(camera);
  RenderRequest oracle;
  oracle.method = "oracle";
  oracle.width = 96;
  oracle.height = 96;
  const ImageRGBA8 expected = render(fine, camera, oracle).image;
  const FragmentLists lists = castFragments(coarse, camera, oracle.width, oracle.height);
  const ImageRGBA8 sampled = render(coarse, camera, oracle).image;
  const OffEdgeComparison c = compareOffEdges(lists, expected, sampled, 2, [](int, int, int) {});
  EXPECT_GT(c.compared, 4000u);
  EXPECT_GE(c.within, c.compared * 999 / 1000) << "max difference " << c.maxDifference;
  for (const char* method : {"abuffer-ll", "kplus-array"}) {
    SCOPED_TRACE(method);
    RenderRequest req = oracle;
    req.method = method;
    if (std::string(method) == "kplus-array") req.params["k"] = "2";
    const OracleMatch m = expectGpuMatchesOracle(coarse, camera, req);
    EXPECT_GT(m.lists.compared, 4000u);
    const OffEdgeComparison g = compareOffEdges(lists, expected, m.out.image, 2, [](int, int, int) {});
    EXPECT_GE(g.within, g.compared * 999 / 1000) << "max difference " << g.maxDifference;
  }
}

// Where the ray through pixel px's centre (image rows top-down) meets the plane z = planeZ.
glm::dvec3 pixelRayHitAtZ(const Camera& camera, int w, int h, const glm::ivec2& px, double planeZ) {
  const glm::dmat4 toWorld = glm::inverse(camera.projectionMatrix(static_cast<double>(w) / h) * camera.viewMatrix());
  const glm::dvec2 ndc(2.0 * (px.x + 0.5) / w - 1.0, 1.0 - 2.0 * (px.y + 0.5) / h);
  const glm::dvec4 a = toWorld * glm::dvec4(ndc, -1.0, 1.0), b = toWorld * glm::dvec4(ndc, 1.0, 1.0);
  const glm::dvec3 origin = glm::dvec3(a) / a.w, dir = glm::dvec3(b) / b.w - origin;
  return origin + ((planeZ - origin.z) / dir.z) * dir;
}

// A section cap coloured by the volume it cuts shows the volume's values inside it (ParaView's
// slice), not a blend of its rim: the probe's value at pixels inside the cap is x·y where the
// pixel's ray meets the plane z = 0, and the GPU draws the cap as the oracle does.
TEST(FieldColorsGpu, SectionCapsShowTheVolumeInside) {
  context();
  Scene scene;
  scene.name = "capped";
  scene.volumes = {xyVolume()};
  Object ball;
  ball.name = "ball";
  ball.mesh = std::make_shared<Mesh>(makeSphere(1.2, 48, 24));
  scene.objects = {ball};
  addVolumeFields(scene);
  colorByField(scene.objects[0], "@xy", "rainbow", glm::dvec2(-1.0, 1.0));
  scene.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, true};
  SectionReport report;
  const Scene cut = sectionedScene(scene, &report);
  ASSERT_EQ(report.capped, 1u);
  Camera camera;
  camera.eye = {0.3, 0.2, 4.0};
  camera.target = {0.0, 0.0, 0.0};
  camera = cut.fit(camera);
  const int w = 80, h = 80;
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = w;
  req.height = h;
  const OracleMatch m = expectGpuMatchesOracle(cut, camera, req);
  EXPECT_GT(m.lists.compared, 2000u);

  int probed = 0;
  for (const glm::ivec2 px : {glm::ivec2(30, 30), glm::ivec2(52, 28), glm::ivec2(47, 50), glm::ivec2(28, 47)}) {
    SCOPED_TRACE(::testing::Message() << "pixel " << px.x << "," << px.y);
    const glm::dvec3 hit = pixelRayHitAtZ(camera, w, h, px, 0.0);
    ASSERT_LT(glm::length(glm::dvec2(hit)), 1.0);  // well inside the cap
    const PixelProbe probe = probePixel(cut, camera, w, h, px.x, px.y);
    ASSERT_FALSE(probe.fragments.empty());
    const ProbeFragment& front = probe.fragments.front();  // the cap, nearest the camera
    ASSERT_TRUE(front.hasValue);
    EXPECT_NEAR(front.value, hit.x * hit.y, 1e-4);
    ++probed;
  }
  EXPECT_EQ(probed, 4);
}

// SectionPlane::slice: the volume's slice on the plane shows the volume at each point — the
// probe's value at pixels on it is x·y where the ray meets it — and the GPU draws it, over a
// capped part in front of it, as the oracle does.
TEST(FieldColorsGpu, AVolumeSliceShowsTheVolumeOnThePlane) {
  context();
  Scene scene;
  scene.name = "sliced";
  scene.volumes = {xyVolume()};
  scene.volumes[0].visible = true;
  Object ball;
  ball.name = "ball";
  ball.mesh = std::make_shared<Mesh>(makeSphere(0.6, 32, 16));
  ball.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.8, 0.5, 0.0));
  ball.material.color = {0.9f, 0.3f, 0.1f, 0.6f};
  scene.objects = {ball};
  scene.section = SectionPlane{{0.0, 0.0, 0.25}, {0.0, 0.0, -1.0}, true, true};
  SectionReport report;
  const Scene cut = sectionedScene(scene, &report);
  ASSERT_EQ(report.slices, 1u);
  ASSERT_EQ(report.capped, 1u);
  ASSERT_EQ(cut.objects.back().name, "xy slice");
  Camera camera;
  camera.eye = {-0.4, -0.6, 4.0};
  camera.target = {0.0, 0.0, 0.0};
  camera = cut.fit(camera);
  const int w = 80, h = 80;
  RenderRequest req;
  req.method = "abuffer-ll";
  req.operation = "oit";
  req.width = w;
  req.height = h;
  const OracleMatch m = expectGpuMatchesOracle(cut, camera, req);
  EXPECT_GT(m.lists.compared, 4000u);

  int probed = 0;
  // The slice lies 10⁻⁴ of the box's diagonal behind the plane (sectionedScene), so caps are in front.
  const Bounds box = scene.volumes[0].bounds();
  const double sliceZ = 0.25 - 1e-4 * glm::length(box.max - box.min);
  for (const glm::ivec2 px : {glm::ivec2(20, 20), glm::ivec2(25, 60), glm::ivec2(40, 40), glm::ivec2(50, 30)}) {
    SCOPED_TRACE(::testing::Message() << "pixel " << px.x << "," << px.y);
    const glm::dvec3 hit = pixelRayHitAtZ(camera, w, h, px, sliceZ);
    ASSERT_LT(std::max(std::abs(hit.x), std::abs(hit.y)), 1.9);  // inside the volume's box
    const PixelProbe probe = probePixel(cut, camera, w, h, px.x, px.y);
    const auto slice = std::find_if(probe.fragments.begin(), probe.fragments.end(), [&](const ProbeFragment& f) {
      return cut.objects[f.fragment.objectId].name == "xy slice";
    });
    ASSERT_NE(slice, probe.fragments.end());
    ASSERT_TRUE(slice->hasValue);
    EXPECT_NEAR(slice->value, hit.x * hit.y, 1e-4);
    ++probed;
  }
  EXPECT_EQ(probed, 4);
}

}  // namespace
}  // namespace mfr::test
