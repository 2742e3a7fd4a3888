// Surfaces coloured by a field (scene/color_map.hpp): the colour maps against published values and
// their defining properties, the value → colour arithmetic, the fields of a mesh and colorByField,
// the oracle's colours against the map of the analytic field at each pixel, the section carrying
// the field onto its cut and caps, and the .mfrscene "color_by" key.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <glm/gtc/packing.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/reference/probe.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/section.hpp"
#include "test_files.hpp"

namespace mfr {
namespace {

// CIE L* of an sRGB colour (IEC 61966-2-1 decoding, D65): lightness, to check a map's ordering.
double lightness(const glm::vec3& srgb) {
  const auto linear = [](double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
  const double y = 0.2126 * linear(srgb.r) + 0.7152 * linear(srgb.g) + 0.0722 * linear(srgb.b);
  return y > 216.0 / 24389.0 ? 116.0 * std::cbrt(y) - 16.0 : y * 24389.0 / 27.0;
}

glm::ivec3 bytes(const glm::vec3& c) {
  return glm::ivec3(glm::round(c * 255.0f));
}

TEST(ColorMaps, CoolWarmIsMorelandsDivergingMap) {
  // Moreland, "Diverging Color Maps for Scientific Visualization" (ISVC 2009), the cool-to-warm
  // table: 0 → (59, 76, 192), 0.5 → (221, 221, 221), 1 → (180, 4, 38).
  const ColorMap& m = colorMap("cool-warm");
  ASSERT_EQ(m.table.size(), static_cast<std::size_t>(MFR_COLOR_MAP_SIZE));
  EXPECT_EQ(bytes(mapFieldValue(m, 0.0f, {0.0f, 1.0f})), glm::ivec3(59, 76, 192));
  EXPECT_EQ(bytes(mapFieldValue(m, 1.0f, {0.0f, 1.0f})), glm::ivec3(180, 4, 38));
  const glm::ivec3 middle = bytes(mapFieldValue(m, 0.5f, {0.0f, 1.0f}));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(middle[c], 221, 1) << c;
  // Diverging: lightness rises to the middle and falls after it.
  for (int i = 1; i < MFR_COLOR_MAP_SIZE; ++i) {
    const double before = lightness(m.table[static_cast<std::size_t>(i - 1)]),
                 now = lightness(m.table[static_cast<std::size_t>(i)]);
    if (i < MFR_COLOR_MAP_SIZE / 2 - 1) {
      EXPECT_GT(now, before - 1e-9) << i;
    }
    if (i > MFR_COLOR_MAP_SIZE / 2 + 1) {
      EXPECT_LT(now, before + 1e-9) << i;
    }
  }
}

TEST(ColorMaps, SequentialMapsRiseInLightness) {
  for (const char* name : {"viridis", "magma", "grayscale"}) {
    SCOPED_TRACE(name);
    const ColorMap& m = colorMap(name);
    for (int i = 1; i < MFR_COLOR_MAP_SIZE; ++i)
      EXPECT_GT(lightness(m.table[static_cast<std::size_t>(i)]), lightness(m.table[static_cast<std::size_t>(i - 1)]))
          << i;
  }
  // matplotlib's end colours: viridis #440154 → #FDE725, magma #000004 → #FCFDBF.
  EXPECT_EQ(bytes(colorMap("viridis").table.front()), glm::ivec3(0x44, 0x01, 0x54));
  EXPECT_EQ(bytes(colorMap("viridis").table.back()), glm::ivec3(0xFD, 0xE7, 0x25));
  EXPECT_EQ(bytes(colorMap("magma").table.front()), glm::ivec3(0x00, 0x00, 0x04));
  EXPECT_EQ(bytes(colorMap("magma").table.back()), glm::ivec3(0xFC, 0xFD, 0xBF));
  EXPECT_EQ(bytes(colorMap("grayscale").table[128]), glm::ivec3(128, 128, 128));
}

TEST(ColorMaps, RainbowRunsFromBlueThroughGreenToRed) {
  const ColorMap& m = colorMap("rainbow");
  EXPECT_EQ(bytes(mapFieldValue(m, 0.0f, {0.0f, 1.0f})), glm::ivec3(0, 0, 255));
  EXPECT_EQ(bytes(mapFieldValue(m, 1.0f, {0.0f, 1.0f})), glm::ivec3(255, 0, 0));
  // Hue 2/3 → 0: a third of the way down is cyan-green, the middle pure green, two thirds yellow.
  // (0.5 lies between two of the table's 256 entries: within one 8-bit step.)
  const glm::ivec3 green = bytes(mapFieldValue(m, 0.5f, {0.0f, 1.0f}));
  EXPECT_LE(green.r, 1);
  EXPECT_EQ(green.g, 255);
  EXPECT_LE(green.b, 1);
  const glm::ivec3 yellow = bytes(mapFieldValue(m, 0.75f, {0.0f, 1.0f}));
  EXPECT_GE(yellow.r, 250);
  EXPECT_GE(yellow.g, 250);
  EXPECT_LE(yellow.b, 5);
}

TEST(ColorMaps, ValuesAreClampedInterpolatedAndNaNHasItsColour) {
  const ColorMap& m = colorMap("grayscale");
  const glm::vec2 range(10.0f, 20.0f);
  EXPECT_EQ(mapFieldValue(m, 5.0f, range), m.table.front());
  EXPECT_EQ(mapFieldValue(m, 25.0f, range), m.table.back());
  EXPECT_EQ(mapFieldValue(m, std::numeric_limits<float>::quiet_NaN(), range), glm::vec3(1.0f, 0.0f, 0.0f));
  // Between two entries: linear. 15 is at x = 127.5 of 255.
  const glm::vec3 half = 0.5f * (m.table[127] + m.table[128]);
  EXPECT_NEAR(mapFieldValue(m, 15.0f, range).r, half.r, 1e-6f);
  EXPECT_NEAR(mapFieldValue(m, 12.5f, range).g, 0.25f, 1e-6f);
  // Before interpolation vertices are bounded to the range ± 1000 spans; NaN stays missing.
  EXPECT_EQ(boundFieldValue(std::numeric_limits<float>::infinity(), {0.0f, 1.0f}), 1001.0f);
  EXPECT_EQ(boundFieldValue(-std::numeric_limits<float>::infinity(), {0.0f, 1.0f}), -1000.0f);
  EXPECT_EQ(boundFieldValue(0.25f, {0.0f, 1.0f}), 0.25f);
  EXPECT_TRUE(std::isnan(boundFieldValue(std::numeric_limits<float>::quiet_NaN(), {0.0f, 1.0f})));
  // An empty range maps everything to the middle.
  EXPECT_NEAR(mapFieldValue(m, 3.0f, {1.0f, 1.0f}).b, 0.5f, 1e-6f);
  EXPECT_EQ(colorMapNames().size(), 5u);
  EXPECT_EQ(colorMapIndex("viridis"), 1);
  try {
    (void)colorMap("jet");
    FAIL() << "an unknown map was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("jet"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("viridis"), std::string::npos);
  }
}

// A 20 × 20 square at z = 0 facing +Z, two triangles; fields: "x" (point data, the x coordinate),
// "v" (point data, (x, y, 3)), "tri" (cell data, the triangle's index).
std::shared_ptr<Mesh> square() {
  auto m = std::make_shared<Mesh>();
  m->positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
  m->normals.assign(4, glm::vec3(0, 0, 1));
  m->indices = {0, 1, 2, 0, 2, 3};
  MeshField x{"x", false, 1, {}}, v{"v", false, 3, {}};
  for (const glm::vec3& p : m->positions) {
    x.values.push_back(p.x);
    v.values.insert(v.values.end(), {p.x, p.y, 3.0f});
  }
  m->fields = {x, v, MeshField{"tri", true, 1, {0.0f, 1.0f}}};
  return m;
}

TEST(FieldColoring, FieldsByNameComponentAndMagnitude) {
  const std::shared_ptr<Mesh> m = square();
  m->validate("square");
  EXPECT_EQ(fieldNames(*m), (std::vector<std::string>{"x", "v", "v:1", "v:2", "v:magnitude", "tri"}));
  EXPECT_EQ(fieldValues(*m, "v:1", "square").values, (std::vector<float>{-10, -10, 10, 10}));
  EXPECT_EQ(fieldValues(*m, "v", "square").values, (std::vector<float>{-10, 10, 10, -10}));
  const std::vector<float> length = fieldValues(*m, "v:magnitude", "square").values;
  ASSERT_EQ(length.size(), 4u);
  for (float l : length) EXPECT_NEAR(l, std::sqrt(209.0f), 1e-5f);
  EXPECT_TRUE(fieldValues(*m, "tri", "square").cellData);
  EXPECT_EQ(fieldRange(fieldValues(*m, "x", "square").values), glm::dvec2(-10.0, 10.0));
  EXPECT_EQ(fieldRange({4.0f, 4.0f}), glm::dvec2(3.0, 5.0));
  // Within float rounding of a constant (an isosurface coloured by its own volume: 0.5 ± a few
  // steps) is a constant: its middle ± 1, not its rounding noise over the whole map.
  {
    const glm::dvec2 r = fieldRange({std::nextafter(0.5f, 0.0f), 0.5f, std::nextafter(0.5f, 1.0f)});
    EXPECT_NEAR(r.x, -0.5, 1e-6);
    EXPECT_NEAR(r.y, 1.5, 1e-6);
  }
  // A small span that is not rounding is kept, however small its values.
  EXPECT_EQ(fieldRange({0.0f, 1e-30f}), glm::dvec2(0.0, double(1e-30f)));
  EXPECT_EQ(fieldRange({1000.0f, 1000.1f}), glm::dvec2(1000.0, double(1000.1f)));
  // A large constant: ±1 would be the same float (1e8 ± 1), and the renderers refused the range.
  for (const float big : {1e8f, -3e20f, std::numeric_limits<float>::max()}) {
    const glm::dvec2 r = fieldRange({big, big});
    EXPECT_LT(static_cast<float>(r.x), static_cast<float>(r.y)) << big;
    EXPECT_TRUE(std::isfinite(static_cast<float>(r.y) - static_cast<float>(r.x))) << big;
    EXPECT_LE(r.x, big);
    EXPECT_GE(r.y, big);
    // A constant volume's default transfer function likewise (1e8 … 1e8 as floats was empty).
    VolumeGrid constant;
    constant.dims = {2, 2, 2};
    constant.values.assign(8, big);
    const TransferFunction tf = defaultTransfer(constant, Bounds{});
    EXPECT_LT(static_cast<float>(tf.low()), static_cast<float>(tf.high())) << big;
  }
  EXPECT_EQ(fieldRange({std::numeric_limits<float>::quiet_NaN(), 2.0f, 7.0f}), glm::dvec2(2.0, 7.0));
  EXPECT_EQ(fieldRange({}), glm::dvec2(0.0, 1.0));
  try {
    (void)fieldValues(*m, "pressure", "square");
    FAIL();
  } catch (const FieldNotFound& e) {
    EXPECT_EQ(std::string(e.what()),
              "square: no point-data or cell-data array 'pressure' (fields: x, v, v:1, v:2, v:magnitude, tri)");
  }
  EXPECT_THROW((void)fieldValues(*m, "v:3", "square"), FieldNotFound);
  EXPECT_THROW((void)fieldValues(*m, "x:1", "square"), FieldNotFound);
  // A field whose size does not match the mesh is refused by validate.
  Mesh bad = *m;
  bad.fields[2].values.push_back(2.0f);
  EXPECT_THROW(bad.validate("bad"), Error);
}

TEST(FieldColoring, ColorByFieldGivesTheObjectItsOwnMeshWithTheValues) {
  Object a, b;
  a.name = "a";
  a.mesh = square();
  b.mesh = a.mesh;
  colorByField(a, "x", "viridis");
  EXPECT_NE(a.mesh, b.mesh);  // b keeps the shared mesh, uncoloured
  EXPECT_TRUE(b.mesh->scalars.empty());
  EXPECT_EQ(a.mesh->scalars, (std::vector<float>{-10, 10, 10, -10}));
  ASSERT_TRUE(a.material.fieldColors);
  EXPECT_EQ(*a.material.fieldColors, (FieldColors{"x", "viridis", {-10.0, 10.0}}));
  // Cell data: each triangle gets its own corners, its value at all three; point fields follow.
  colorByField(a, "tri", "magma", glm::dvec2(-1.0, 2.0));
  a.mesh->validate("a");
  EXPECT_EQ(a.mesh->positions.size(), 6u);
  EXPECT_EQ(a.mesh->scalars, (std::vector<float>{0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(a.mesh->positions[4], glm::vec3(10, 10, 0));
  EXPECT_EQ(fieldValues(*a.mesh, "x", "a").values, (std::vector<float>{-10, 10, 10, -10, 10, -10}));
  EXPECT_EQ(a.material.fieldColors->range, glm::dvec2(-1.0, 2.0));
  // Refusals name the object; the object is unchanged by a refusal.
  const std::shared_ptr<const Mesh> before = a.mesh;
  EXPECT_THROW(colorByField(a, "x", "jet"), Error);
  EXPECT_THROW(colorByField(a, "x", "viridis", glm::dvec2(1.0, 1.0)), Error);
  EXPECT_THROW(colorByField(a, "x", "viridis", glm::dvec2(0.0, std::nan(""))), Error);
  try {
    colorByField(a, "p", "viridis");
    FAIL();
  } catch (const FieldNotFound& e) {
    EXPECT_EQ(std::string(e.what()).rfind("a: no point-data or cell-data array 'p'", 0), 0u) << e.what();
  }
  EXPECT_EQ(a.mesh, before);
  EXPECT_EQ(a.material.fieldColors->map, "magma");
}

// Orthographic camera from +Z showing 20 × 20 world units on 40 × 40 pixels: pixel (c, r) has its
// centre at x = (c + 0.5)/2 − 10, y = 10 − (r + 0.5)/2.
Camera topCamera() {
  Camera c;
  c.eye = {0.0, 0.0, 10.0};
  c.projection = Projection::Orthographic;
  c.orthoHeight = 20.0;
  c.nearPlane = 1.0;
  c.farPlane = 20.0;
  return c;
}

TEST(FieldColoring, TheOracleMapsTheFieldInterpolatedAtEachHit) {
  Scene scene;
  scene.name = "square";
  Object o;
  o.name = "square";
  o.mesh = square();
  o.material.color = {0.2f, 0.9f, 0.1f, 1.0f};  // opaque; its RGB must not show
  colorByField(o, "x", "cool-warm", glm::dvec2(-5.0, 5.0));
  scene.objects.push_back(o);
  const FragmentLists lists = castFragments(scene, topCamera(), 40, 40);
  const ColorMap& map = colorMap("cool-warm");
  int compared = 0;
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) {
      if (lists.isAmbiguous(c, r)) continue;
      ASSERT_EQ(lists.count(c, r), 1u);
      // Head-on: the headlight gives full light, so the colour is the map's at the pixel's x.
      const float x = (static_cast<float>(c) + 0.5f) / 2.0f - 10.0f;
      const glm::vec4 shaded = glm::unpackUnorm4x8(lists.pixel(c, r)[0].color);
      const glm::vec3 expected = mapFieldValue(map, x, {-5.0f, 5.0f});
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(shaded[ch], expected[ch], 1.0f / 255.0f) << c << "," << r;
      EXPECT_NEAR(shaded.a, 1.0f, 1e-6f);
      ++compared;
    }
  EXPECT_GT(compared, 1400);
  // Cell data: one colour per triangle (the diagonal from (−10,−10) to (10,10) splits them).
  scene.objects[0].mesh = square();
  colorByField(scene.objects[0], "tri", "grayscale", glm::dvec2(0.0, 1.0));
  const FragmentLists cells = castFragments(scene, topCamera(), 40, 40);
  const glm::vec4 below = glm::unpackUnorm4x8(cells.pixel(30, 35)[0].color);  // x > y: triangle 0
  const glm::vec4 above = glm::unpackUnorm4x8(cells.pixel(5, 4)[0].color);    // triangle 1
  EXPECT_EQ(glm::ivec3(glm::round(glm::vec3(below) * 255.0f)), glm::ivec3(0));
  EXPECT_EQ(glm::ivec3(glm::round(glm::vec3(above) * 255.0f)), glm::ivec3(255));
}

TEST(FieldColoring, ASectionCarriesTheFieldOntoItsCutAndCaps) {
  Scene scene;
  scene.name = "box";
  Object o;
  o.name = "box";
  auto mesh = std::make_shared<Mesh>(makeBox({2.0, 2.0, 2.0}));
  MeshField x{"x", false, 1, {}};
  for (const glm::vec3& p : mesh->positions) x.values.push_back(p.x);
  mesh->fields.push_back(x);
  o.mesh = mesh;
  colorByField(o, "x");
  scene.objects.push_back(o);
  scene.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, true};
  const Scene cut = sectionedScene(scene);
  const Mesh& m = *cut.objects[0].mesh;
  ASSERT_EQ(m.scalars.size(), m.positions.size());
  // The field is x everywhere, on the cut line and on the cap alike.
  int onPlane = 0;
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_NEAR(m.scalars[i], m.positions[i].x, 1e-5f) << i;
    onPlane += std::abs(m.positions[i].z) < 1e-6f ? 1 : 0;
  }
  EXPECT_GT(onPlane, 4);
  EXPECT_TRUE(cut.objects[0].material.fieldColors);
}

TEST(FieldColoring, TheProbeGivesTheFieldValueAtEachFragment) {
  // Two squares facing the camera: in front (z = 0) coloured by x, behind (z = −2) first by
  // nothing, then by v:1 (= y). Orthographic from +Z, 20 × 20 units on 40 × 40 pixels.
  Scene scene;
  scene.name = "squares";
  for (const double z : {0.0, -2.0}) {
    Object o;
    o.name = z == 0.0 ? "front" : "back";
    o.mesh = square();
    o.transform[3] = glm::dvec4(0.0, 0.0, z, 1.0);
    o.material.color.a = 0.5f;
    scene.objects.push_back(o);
  }
  colorByField(scene.objects[0], "x", "viridis");
  for (const auto& [c, r] : {std::pair{3, 5}, {20, 20}, {37, 11}, {26, 33}}) {
    const PixelProbe p = probePixel(scene, topCamera(), 40, 40, c, r);
    ASSERT_EQ(p.fragments.size(), 2u);
    EXPECT_TRUE(p.fragments[0].hasValue);
    EXPECT_NEAR(p.fragments[0].value, (c + 0.5) / 2.0 - 10.0, 1e-4) << c << "," << r;
    EXPECT_FALSE(p.fragments[1].hasValue);
  }
  colorByField(scene.objects[1], "v:1", "magma");
  const PixelProbe p = probePixel(scene, topCamera(), 40, 40, 26, 33);
  ASSERT_EQ(p.fragments.size(), 2u);
  EXPECT_NEAR(p.fragments[0].value, 26.5 / 2.0 - 10.0, 1e-4);
  ASSERT_TRUE(p.fragments[1].hasValue);
  EXPECT_NEAR(p.fragments[1].value, 10.0 - 33.5 / 2.0, 1e-4);
}

// A volume's values at the parts' vertices: a grid whose value is 2x − y + 3z (trilinear
// interpolation reproduces it exactly) sampled on a moved sphere, NaN beyond half a voxel outside
// the grid's box.
TEST(FieldColoring, VolumesAreSampledAtEveryVertex) {
  Scene scene;
  scene.name = "ramp";
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = {9, 7, 5};
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 7; ++j)
      for (int i = 0; i < 9; ++i) {
        const glm::dvec3 p = glm::dvec3(-2.0, -1.5, -1.0) + 0.5 * glm::dvec3(i, j, k);  // origin + spacing · index
        grid->values.push_back(static_cast<float>(2.0 * p.x - p.y + 3.0 * p.z));
      }
  Volume volume;
  volume.name = "ramp";
  volume.grid = grid;
  volume.origin = {-2.0, -1.5, -1.0};
  volume.spacing = {0.5, 0.5, 0.5};
  volume.transfer = defaultTransfer(*grid, volume.bounds());
  scene.volumes.push_back(volume);
  Object inside, across;
  inside.name = "inside";
  inside.mesh = std::make_shared<Mesh>(makeSphere(0.5, 12, 6));
  inside.transform[3] = glm::dvec4(0.4, 0.2, -0.1, 1.0);
  across.name = "across";
  across.mesh = inside.mesh;
  across.transform[3] = glm::dvec4(2.0, 0.0, 0.0, 1.0);  // half of it beyond x = 2
  scene.objects = {inside, across};
  addVolumeFields(scene);
  EXPECT_NE(scene.objects[0].mesh, scene.objects[1].mesh);  // instances sample their own places
  for (const Object& o : scene.objects) {
    SCOPED_TRACE(o.name);
    const FieldValues v = fieldValues(*o.mesh, "@ramp", o.name);
    std::size_t outside = 0;
    for (std::size_t i = 0; i < v.values.size(); ++i) {
      const glm::dvec3 p(o.transform * glm::dvec4(glm::dvec3(o.mesh->positions[i]), 1.0));
      // Up to half a voxel (0.25) beyond the last sample: the face's value; farther: none.
      if (p.x > 2.25 + 1e-6) {
        EXPECT_TRUE(std::isnan(v.values[i])) << i;
        ++outside;
      } else {
        EXPECT_NEAR(v.values[i], 2.0 * std::min(p.x, 2.0) - p.y + 3.0 * p.z, 1e-4) << i;
      }
    }
    EXPECT_EQ(outside > 0, o.name == "across");
  }
  // Idempotent: a second call adds nothing.
  const std::shared_ptr<const Mesh> before = scene.objects[0].mesh;
  addVolumeFields(scene);
  EXPECT_EQ(scene.objects[0].mesh, before);
  EXPECT_EQ(fieldNames(*scene.objects[0].mesh), (std::vector<std::string>{"@ramp"}));
}

// PLY files carry fields as extra scalar properties (MeshLab's "quality", a scanner's
// "confidence"): per vertex and per face, ASCII and binary alike.
TEST(FieldColoring, PlyScalarPropertiesAreFields) {
  const test::TempDir dir;
  // Five vertices: a unit square and one corner above it; a triangle and a quad.
  const float xyz[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 1}};
  std::string header =
      "ply\nformat FORMAT 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nproperty float quality\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nproperty uchar confidence\nelement face 2\n"
      "property list uchar int vertex_indices\nproperty int flags\nend_header\n";
  std::string ascii = header, binary = header;
  ascii.replace(ascii.find("FORMAT"), 6, "ascii");
  binary.replace(binary.find("FORMAT"), 6, "binary_little_endian");
  const auto put = [&binary](const auto& v) { binary.append(reinterpret_cast<const char*>(&v), sizeof(v)); };
  for (int v = 0; v < 5; ++v) {
    const float quality = 10.0f * xyz[v][0] + xyz[v][1];
    const auto confidence = static_cast<std::uint8_t>(50 * v);
    ascii += std::to_string(xyz[v][0]) + " " + std::to_string(xyz[v][1]) + " " + std::to_string(xyz[v][2]) + " " +
             std::to_string(quality) + " 200 100 50 " + std::to_string(confidence) + "\n";
    for (float c : xyz[v]) put(c);
    put(quality);
    put(std::uint8_t{200});
    put(std::uint8_t{100});
    put(std::uint8_t{50});
    put(confidence);
  }
  ascii += "3 1 4 2 7\n4 0 1 2 3 -3\n";
  put(std::uint8_t{3});
  for (int i : {1, 4, 2}) put(i);
  put(7);
  put(std::uint8_t{4});
  for (int i : {0, 1, 2, 3}) put(i);
  put(-3);
  for (const auto& [file, bytes] : {std::pair{"a.ply", ascii}, {"b.ply", binary}}) {
    SCOPED_TRACE(file);
    const std::vector<Object> parts = loadModel(dir.write(file, bytes));
    ASSERT_EQ(parts.size(), 1u);
    const Mesh& m = *parts[0].mesh;
    EXPECT_EQ(fieldNames(m), (std::vector<std::string>{"quality", "confidence", "flags"}));
    ASSERT_EQ(m.colors.size(), m.positions.size());  // red, green, blue stay colours
    const FieldValues quality = fieldValues(m, "quality", file), confidence = fieldValues(m, "confidence", file);
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      const glm::vec3 p = m.positions[v];
      EXPECT_FLOAT_EQ(quality.values[v], 10.0f * p.x + p.y) << v;
      int corner = 0;
      while (corner < 5 && glm::vec3(xyz[corner][0], xyz[corner][1], xyz[corner][2]) != p) ++corner;
      EXPECT_EQ(confidence.values[v], 50.0f * static_cast<float>(corner)) << v;
    }
    // The triangle (its corner at z = 1) has flags 7, the quad's two triangles −3.
    const FieldValues flags = fieldValues(m, "flags", file);
    ASSERT_TRUE(flags.cellData);
    ASSERT_EQ(flags.values.size(), 3u);
    for (std::size_t t = 0; t < 3; ++t) {
      bool raised = false;
      for (int k = 0; k < 3; ++k)
        raised = raised || m.positions[m.indices[3 * t + static_cast<std::size_t>(k)]].z > 0.5f;
      EXPECT_EQ(flags.values[t], raised ? 7.0f : -3.0f) << t;
    }
  }
}

}  // namespace
}  // namespace mfr
