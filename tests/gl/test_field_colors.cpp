// Surfaces coloured by a field on the GPU (common/color_map.glsl: the value interpolated across the
// triangle, then mapped through the map's table) against the oracle, which interpolates at the ray's
// hit and maps with mfr::mapFieldValue: point data and cell data, several maps, through the exact
// methods, a k-buffer and depth peeling, and on a sectioned scene whose caps carry the field.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
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

}  // namespace
}  // namespace mfr::test
