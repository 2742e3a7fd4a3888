// Isosurfaces (scene/contour.hpp) against references that share none of VTK's extractor: the
// volume's own trilinear sampler (every vertex must sample to the value), closed forms (a sphere's
// radius, area and enclosed volume; a plane's area and normal), the topology of a closed surface
// (every edge shared by two triangles, wound consistently, Euler characteristic 2), and the
// request's checks, which must leave the scene as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mfr/error.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/scene/scene_file.hpp"
#include "test_files.hpp"

namespace mfr::test {
namespace {

// [-1, 1]³ sampled by nx × ny × nz points (spacing differs per axis) with values f(p).
template <class F>
Volume boxVolume(glm::ivec3 n, F f) {
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = n;
  const glm::dvec3 h = 2.0 / glm::dvec3(n - 1);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        grid->values.push_back(static_cast<float>(f(glm::dvec3(-1.0) + glm::dvec3(i, j, k) * h)));
  Volume v;
  v.name = "box";
  v.grid = grid;
  v.origin = glm::dvec3(-1.0);
  v.spacing = h;
  return v;
}

const glm::ivec3 kDims{41, 51, 31};  // anisotropic, so that a mix-up of axes or spacings shows

double triangleArea(const Mesh& m, std::size_t t) {
  const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

double area(const Mesh& m) {
  double sum = 0.0;
  for (std::size_t t = 0; t < m.indices.size(); t += 3) sum += triangleArea(m, t);
  return sum;
}

// Σ over triangles of a · (b × c) / 6: the enclosed volume of a closed surface, positive when its
// triangles wind counter-clockwise seen from outside.
double signedVolume(const Mesh& m) {
  double sum = 0.0;
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
    sum += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return sum;
}

// The grid coordinates of an object-space point of `v`.
glm::vec3 gridCoords(const Volume& v, const glm::vec3& p) {
  return glm::vec3((glm::dvec3(p) - v.origin) / v.spacing);
}

TEST(Contour, SphereOfADensityLiesOnTheValueIsClosedAndFacesOutwards) {
  const double r = 0.6;
  const Volume v = boxVolume(kDims, [](glm::dvec3 p) { return 1.0 - glm::length(p); });
  const double value = 1.0 - r;
  const Mesh m = contourVolume(v, value);
  ASSERT_GT(m.triangleCount(), 1000u);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  m.validate("sphere");

  double worstSample = 0.0, worstRadius = 0.0, worstNormal = 1.0;
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::vec3 p = m.positions[i];
    // On a grid edge the trilinear sample is the edge's linear interpolation: exactly the value.
    worstSample = std::max(worstSample, std::abs(static_cast<double>(v.grid->sample(gridCoords(v, p))) - value));
    worstRadius = std::max(worstRadius, std::abs(glm::length(glm::dvec3(p)) - r));
    worstNormal = std::min(worstNormal, static_cast<double>(glm::dot(m.normals[i], glm::normalize(p))));
  }
  EXPECT_LT(worstSample, 1e-5);
  // |p| is convex along an edge: linear interpolation errs by at most h²/(8r), h ≤ 0.067.
  EXPECT_LT(worstRadius, 0.0015);
  EXPECT_GT(worstNormal, 0.99);  // the gradient of 1 − |p| points inwards: normals point out

  // Closed and consistently wound: every directed edge once, its reverse once.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t t = 0; t < m.indices.size(); t += 3)
    for (int e = 0; e < 3; ++e) ++directed[{m.indices[t + e], m.indices[t + (e + 1) % 3]}];
  std::size_t unpaired = 0, repeated = 0;
  for (const auto& [edge, count] : directed) {
    repeated += count != 1;
    unpaired += directed.count({edge.second, edge.first}) == 0;
  }
  EXPECT_EQ(repeated, 0u);
  EXPECT_EQ(unpaired, 0u);
  const long long vertices = static_cast<long long>(m.positions.size());
  const long long edges = static_cast<long long>(directed.size() / 2);
  const long long faces = static_cast<long long>(m.triangleCount());
  EXPECT_EQ(vertices - edges + faces, 2);  // a sphere

  const double pi = glm::pi<double>();
  EXPECT_NEAR(area(m), 4.0 * pi * r * r, 0.01 * 4.0 * pi * r * r);
  EXPECT_NEAR(signedVolume(m), 4.0 / 3.0 * pi * r * r * r, 0.01 * 4.0 / 3.0 * pi * r * r * r);  // > 0: outwards
}

TEST(Contour, SphereOfADistanceFacesTowardsLowerValuesInwards) {
  // The same sphere as the level set of |p|: lower values inside, so the normals point inwards and
  // the triangles wind clockwise seen from outside.
  const double r = 0.6;
  const Volume v = boxVolume(kDims, [](glm::dvec3 p) { return glm::length(p); });
  const Mesh m = contourVolume(v, r);
  ASSERT_GT(m.triangleCount(), 1000u);
  const double pi = glm::pi<double>();
  EXPECT_NEAR(signedVolume(m), -4.0 / 3.0 * pi * r * r * r, 0.01 * 4.0 / 3.0 * pi * r * r * r);
  double worstNormal = 1.0;
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    worstNormal = std::min(worstNormal, static_cast<double>(glm::dot(m.normals[i], -glm::normalize(m.positions[i]))));
  EXPECT_GT(worstNormal, 0.99);
}

TEST(Contour, PlaneAcrossTheGridIsOpenAtItsBoundaryWithTheExactArea) {
  // f = 2z + x/4: the plane z = (0.3 − x/4)/2 crosses the whole box; its area over [-1, 1]² is
  // 4·sqrt(1 + (1/8)²), its normal −∇f/|∇f|.
  const Volume v = boxVolume(kDims, [](glm::dvec3 p) { return 2.0 * p.z + 0.25 * p.x; });
  const Mesh m = contourVolume(v, 0.3);
  ASSERT_GT(m.triangleCount(), 100u);
  EXPECT_NEAR(area(m), 4.0 * std::sqrt(1.0 + 1.0 / 64.0), 1e-4);
  const glm::dvec3 down = -glm::normalize(glm::dvec3(0.25, 0.0, 2.0));
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    if (triangleArea(m, t) < 1e-9) continue;
    const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
    ASSERT_GT(glm::dot(glm::normalize(glm::cross(b - a, c - a)), down), 0.999) << "triangle " << t / 3;
  }
  for (const glm::vec3& n : m.normals) ASSERT_GT(glm::dot(glm::dvec3(n), down), 0.999);
  // Open: edges on the grid's sides belong to one triangle only.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (std::size_t t = 0; t < m.indices.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = m.indices[t + e], b = m.indices[t + (e + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  double boundary = 0.0;  // length of the edges of one triangle
  for (const auto& [edge, count] : edges) {
    if (count == 1) {
      boundary += glm::distance(glm::dvec3(m.positions[edge.first]), glm::dvec3(m.positions[edge.second]));
      const glm::vec3 p = m.positions[edge.first];
      EXPECT_TRUE(std::abs(std::abs(p.x) - 1.0f) < 1e-5f || std::abs(std::abs(p.y) - 1.0f) < 1e-5f)
          << "a boundary edge inside the grid at " << p.x << ", " << p.y;
    }
  }
  // The parallelogram's perimeter: 2 along y at x = ±1, and sqrt(2² + 0.25²) along x at y = ±1.
  EXPECT_NEAR(boundary, 2.0 * 2.0 + 2.0 * std::sqrt(4.0 + 0.0625), 1e-4);
}

TEST(Contour, NoCrossingGivesNoSurface) {
  const Volume v = boxVolume(glm::ivec3(5), [](glm::dvec3 p) { return p.x; });
  EXPECT_EQ(contourVolume(v, 2.0).triangleCount(), 0u);
  EXPECT_EQ(contourVolume(v, -1.5).triangleCount(), 0u);
}

Scene volumeScene() {
  Scene scene;
  scene.name = "s";
  Volume v = boxVolume(glm::ivec3(21), [](glm::dvec3 p) { return 100.0 * (1.0 - glm::length(p)); });
  v.name = "ct";
  v.transform = glm::dmat4(2.0);
  v.transform[3] = glm::dvec4(5.0, 0.0, 0.0, 1.0);
  scene.volumes.push_back(v);
  Object box;
  box.name = "part";
  auto mesh = std::make_shared<Mesh>();
  mesh->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh->normals.assign(3, glm::vec3(0, 0, 1));
  mesh->indices = {0, 1, 2};
  box.mesh = mesh;
  scene.objects.push_back(box);
  return scene;
}

TEST(Contour, AddContoursMakesNamedColouredPartsPlacedLikeTheVolume) {
  Scene scene = volumeScene();
  const glm::vec2 range = scene.volumes[0].grid->range();
  const std::vector<std::size_t> added = addContours(scene, {0, {20.0, 60.0}, 0.25f}, "test");
  ASSERT_EQ(added, (std::vector<std::size_t>{1, 2}));
  ASSERT_EQ(scene.objects.size(), 3u);
  const double values[] = {20.0, 60.0};
  for (std::size_t i = 0; i < 2; ++i) {
    const Object& o = scene.objects[added[i]];
    EXPECT_EQ(o.name, i == 0 ? "ct = 20" : "ct = 60");
    EXPECT_EQ(o.transform, scene.volumes[0].transform);
    // Two values: the map spans them, the first at its blue end, the second at its red end.
    const glm::vec3 rgb = mapFieldValue(colorMap("cool-warm"), i == 0 ? 0.0f : 1.0f, glm::vec2(0.0f, 1.0f));
    EXPECT_EQ(o.material.color, glm::vec4(rgb, 0.25f));
    // Sphere of radius 1 − value/100 in object space.
    const glm::vec3 p = o.mesh->positions.front();
    EXPECT_NEAR(glm::length(p), 1.0 - values[i] / 100.0, 0.01);
    // The volume field every part gets: the value itself on the isosurface.
    ASSERT_TRUE(hasField(*o.mesh, "@ct"));
    for (const float f : fieldValues(*o.mesh, "@ct", "").values) ASSERT_NEAR(f, values[i], 1e-3);
  }
  EXPECT_NE(scene.objects[0].mesh->fields.size(), 0u);  // the other part got it too
  EXPECT_EQ(contourPartName("ct", 0.125), "ct = 0.125");
  // One value: its colour over the grid's range.
  Scene one = volumeScene();
  addContours(one, {0, {20.0}, 1.0f}, "test");
  EXPECT_EQ(one.objects[1].material.color, glm::vec4(mapFieldValue(colorMap("cool-warm"), 20.0f, range), 1.0f));
}

TEST(Contour, AMirroredVolumesIsosurfacesFaceOutwardsInObjectSpaceLikeEveryPart) {
  // A density sphere placed with a mirror (x → −x, as InVesalius projects flip y): like any part,
  // its triangles wind counter-clockwise seen from outside in its own coordinates, and the mirror
  // reverses that in the world (CSG and section caps allow for mirrored parts).
  for (const double mirror : {1.0, -1.0}) {
    Scene scene;
    scene.name = "m";
    Volume v = boxVolume(glm::ivec3(21), [](glm::dvec3 p) { return 1.0 - glm::length(p); });
    v.transform = glm::dmat4(1.0);
    v.transform[0][0] = mirror;
    scene.volumes.push_back(v);
    addContours(scene, {0, {0.5}, 0.5f}, "test");
    const double expected = 4.0 / 3.0 * glm::pi<double>() * 0.125;
    EXPECT_NEAR(signedVolume(*scene.objects.at(0).mesh), expected, 0.05 * expected) << "mirror " << mirror;
    Mesh world = *scene.objects[0].mesh;
    for (glm::vec3& p : world.positions) p = glm::vec3(scene.objects[0].transform * glm::dvec4(glm::dvec3(p), 1.0));
    EXPECT_NEAR(signedVolume(world), mirror * expected, 0.05 * expected) << "mirror " << mirror;
  }
}

void expectRefused(const ContourRequest& request, const std::string& message) {
  Scene scene = volumeScene();
  const std::shared_ptr<const Mesh> before = scene.objects[0].mesh;
  try {
    addContours(scene, request, "--contour");
    ADD_FAILURE() << "accepted; expected: " << message;
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "--contour: " + message);
  }
  EXPECT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].mesh, before);
}

TEST(Contour, BadRequestsAreRefusedAndLeaveTheSceneAsItWas) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  expectRefused({0, {}, 0.5f}, "no value given");
  expectRefused({0, std::vector<double>(kMaxContourValues + 1, 50.0), 0.5f},
                "17 values: at most 16 isosurfaces at once");
  expectRefused({0, {50.0, 200.0}, 0.5f}, "200 lies outside the open range [-73.2051, 100] of volume 'ct': no surface");
  expectRefused({0, {100.0}, 0.5f}, "100 lies outside the open range [-73.2051, 100] of volume 'ct': no surface");
  expectRefused({0, {std::nan("")}, 0.5f}, "the value must be a finite number");
  expectRefused({0, {50.0}, nan}, "opacity must lie in [0, 1]");
  expectRefused({0, {50.0}, 1.5f}, "opacity must lie in [0, 1]");
  expectRefused({3, {50.0}, 0.5f}, "no volume 3 (the scene has 1)");
  Scene empty;
  empty.name = "e";
  EXPECT_THROW(addContours(empty, {0, {1.0}, 0.5f}, "x"), Error);
}

TEST(Contour, SceneFileContoursAddPartsAndNameTheirErrors) {
  TempDir dir;
  // A 3×3×3 legacy VTK grid, 0 outside and 1 at the centre: the isosurface at 0.5 is a closed octahedron-like shell.
  std::string values;
  for (int i = 0; i < 27; ++i) values += i == 13 ? "1 " : "0 ";
  dir.write("g.vtk",
            "# vtk DataFile Version 3.0\ng\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 3 3\n"
            "ORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 27\nSCALARS d float 1\nLOOKUP_TABLE "
            "default\n" +
                values + "\n");
  const auto parse = [&](const std::string& contours) {
    return parseSceneFile(R"({"volumes": [{"file": "g.vtk", "name": "g", "contours": )" + contours + "}]}", dir.path(),
                          "c.mfrscene");
  };
  const Scene a = parse("[0.5, 0.25]");
  ASSERT_EQ(a.objects.size(), 2u);
  EXPECT_EQ(a.objects[0].name, "g = 0.5");
  EXPECT_EQ(a.objects[1].name, "g = 0.25");
  EXPECT_FLOAT_EQ(a.objects[0].material.color.a, 0.5f);
  EXPECT_TRUE(a.volumes[0].visible);  // a scene file says "visible": false itself when it wants that
  // The shell at 0.5 around the centre (1, 1, 1): every vertex half-way along an edge from it.
  for (const glm::vec3& p : a.objects[0].mesh->positions) EXPECT_NEAR(glm::length(p - glm::vec3(1.0f)), 0.5f, 1e-5f);

  const Scene b = parse(R"({"values": [0.75], "opacity": 0.2})");
  ASSERT_EQ(b.objects.size(), 1u);
  EXPECT_FLOAT_EQ(b.objects[0].material.color.a, 0.2f);

  const auto refused = [&](const std::string& contours, const std::string& message) {
    try {
      parse(contours);
      ADD_FAILURE() << contours << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "c.mfrscene: volumes[0].contours" + message) << contours;
    }
  };
  refused("\"0.5\"", R"(: expected an array of values or {"values": [...], "opacity": a})");
  refused("[0.5, \"x\"]", "[1]: expected a number");
  refused("[1.5]", ": 1.5 lies outside the open range [0, 1] of volume 'g': no surface");
  refused("[]", ": no value given");
  refused(R"({"values": [0.5], "opacity": 2})", ".opacity: must be in [0, 1]");
  refused(R"({"value": [0.5]})", ".value: unknown key (expected values, opacity)");
  refused(R"({"opacity": 0.5})", ": needs 'values' (the isosurfaces' values)");
}

}  // namespace
}  // namespace mfr::test
