// The CPU oracle and its exact operations, checked against answers worked out by hand (geometry,
// the projection formula, the "over" formula), never against the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr {
namespace {

void addObject(Scene& scene, Mesh mesh, const glm::dmat4& transform, const glm::vec4& color) {
  Object o;
  o.name = "object" + std::to_string(scene.objects.size());
  o.mesh = std::make_shared<const Mesh>(std::move(mesh));
  o.transform = transform;
  o.material.color = color;
  scene.objects.push_back(std::move(o));
}

// Looking down −Z from (0, 0, 10) at the origin; near 1, far 20.
Camera frontCamera(Projection projection, double orthoHeight = 8.0) {
  Camera c;
  c.eye = {0.0, 0.0, 10.0};
  c.target = {0.0, 0.0, 0.0};
  c.up = {0.0, 1.0, 0.0};
  c.projection = projection;
  c.fovyDegrees = 40.0;
  c.orthoHeight = orthoHeight;
  c.nearPlane = 1.0;
  c.farPlane = 20.0;
  return c;
}

glm::dmat4 translate(double x, double y, double z) {
  return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z));
}

// Concentric spheres of radius 1, 2, 3 (object ids 0, 1, 2), 64×64 pixels.
Scene nestedSpheres() {
  Scene s;
  s.name = "nested";
  for (double r : {1.0, 2.0, 3.0}) addObject(s, makeSphere(r), glm::dmat4(1.0), {0.5f, 0.5f, 0.5f, 0.3f});
  return s;
}

TEST(OracleSpheres, OrthographicCountsDepthsAndFacing) {
  const Scene scene = nestedSpheres();
  const Camera camera = frontCamera(Projection::Orthographic);  // 8 world units over 64 px
  const FragmentLists lists = castFragments(scene, camera, 64, 64);
  ASSERT_EQ(lists.width, 64);
  ASSERT_EQ(lists.offsets.size(), 64u * 64u + 1u);

  // Pixel (32, 29): centre at world (x, y) = ((32.5/32 − 1)·4, ((63 − 29 + 0.5)/32 − 1)·4) =
  // (0.0625, 0.3125), ρ² = x² + y² = 0.1015625, inside all three spheres: in and out of each one.
  // (Pixels on the lines y = ±x lie on the meshes' quad diagonals, so the clean pixel is off them.)
  ASSERT_FALSE(lists.isAmbiguous(32, 29));
  const auto centre = lists.pixel(32, 29);
  ASSERT_EQ(centre.size(), 6u);
  const std::uint32_t ids[6] = {2, 1, 0, 0, 1, 2};
  const bool front[6] = {true, true, true, false, false, false};
  // Orthographic depth is linear: (distance − near)/(far − near), distance = 10 − z with the hit at
  // z = ±sqrt(r² − ρ²).
  const double z[6] = {std::sqrt(9 - 0.1015625),  std::sqrt(4 - 0.1015625),  std::sqrt(1 - 0.1015625),
                       -std::sqrt(1 - 0.1015625), -std::sqrt(4 - 0.1015625), -std::sqrt(9 - 0.1015625)};
  for (int i = 0; i < 6; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(centre[i].objectId, ids[i]);
    EXPECT_EQ(centre[i].frontFacing, front[i]);
    EXPECT_NEAR(centre[i].depth, (10.0 - z[i] - 1.0) / 19.0, 1e-3);  // the mesh lies < 0.013 inside the sphere
    if (i > 0) {
      EXPECT_GT(centre[i].depth, centre[i - 1].depth);
    }
  }

  // Pixel (51, 32): world x = (51.5/32 − 1)·4 = 2.4375 — between radius 2 and 3: only the outer
  // sphere, in and out.
  ASSERT_FALSE(lists.isAmbiguous(51, 32));
  const auto ring = lists.pixel(51, 32);
  ASSERT_EQ(ring.size(), 2u);
  EXPECT_EQ(ring[0].objectId, 2u);
  EXPECT_EQ(ring[1].objectId, 2u);
  EXPECT_TRUE(ring[0].frontFacing);
  EXPECT_FALSE(ring[1].frontFacing);
  EXPECT_LT(ring[0].depth, ring[1].depth);

  // Corners: world distance ≈ 5.5 from the axis, outside everything.
  EXPECT_EQ(lists.count(0, 0), 0u);
  EXPECT_EQ(lists.count(63, 63), 0u);
  EXPECT_EQ(lists.count(0, 63), 0u);
}

TEST(OracleSpheres, PerspectiveCountsAndFacing) {
  const Scene scene = nestedSpheres();
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Perspective), 64, 64);
  // Pixel (33, 31): NDC (0.047, 0.016): the ray passes 0.2 from the centre.
  ASSERT_FALSE(lists.isAmbiguous(33, 31));
  const auto centre = lists.pixel(33, 31);
  ASSERT_EQ(centre.size(), 6u);
  const bool front[6] = {true, true, true, false, false, false};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(centre[i].frontFacing, front[i]) << i;
    if (i > 0) {
      EXPECT_GT(centre[i].depth, centre[i - 1].depth) << i;
    }
  }
  // Pixel (54, 32): NDC x = 54.5/32 − 1 = 0.703, so the ray leaves the axis at tan α = 0.703·tan 20°
  // = 0.256 and passes the centre at 10·sin α = 2.48: between radius 2 and 3.
  ASSERT_FALSE(lists.isAmbiguous(54, 32));
  ASSERT_EQ(lists.count(54, 32), 2u);
  EXPECT_TRUE(lists.pixel(54, 32)[0].frontFacing);
  EXPECT_FALSE(lists.pixel(54, 32)[1].frontFacing);
  EXPECT_EQ(lists.count(1, 1), 0u);
}

// Two 2×2 quads facing the camera, 40×40 px over 4×4 world units (0.1 per pixel): A at z = 0
// centred at the origin, B at z = 1 centred at x = 1. Colours are multiples of 1/255 so that
// 8-bit packing is exact and the hand computation needs no rounding.
Scene overlappingQuads() {
  Scene s;
  s.name = "quads";
  addObject(s, makePlane(2.0, 2.0), glm::dmat4(1.0), {1.0f, 0.6f, 0.2f, 0.4f});           // A
  addObject(s, makePlane(2.0, 2.0), translate(1.0, 0.0, 1.0), {0.2f, 0.4f, 1.0f, 0.6f});  // B, in front
  return s;
}

TEST(CompositeOver, OverlappingQuadsMatchHandComputedOver) {
  const Scene scene = overlappingQuads();
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Orthographic, 4.0), 40, 40);
  // Pixel (25, 19): world (25.5/10 − 2, (39 − 19 + 0.5)/10 − 2) = (0.55, 0.05), inside both quads and
  // 3.5 px from either diagonal.
  ASSERT_FALSE(lists.isAmbiguous(25, 19));
  const auto px = lists.pixel(25, 19);
  ASSERT_EQ(px.size(), 2u);
  EXPECT_EQ(px[0].objectId, 1u);
  EXPECT_EQ(px[1].objectId, 0u);
  // Normal parallel to the view: light = 0.3 + 0.7·1 = 1, so the fragment colour is the material.
  EXPECT_EQ(px[0].color, 0x99FF6633u);  // (51, 102, 255, 153) = (0.2, 0.4, 1.0, 0.6), R in the low byte
  EXPECT_EQ(px[1].color, 0x663399FFu);  // (255, 153, 51, 102) = (1.0, 0.6, 0.2, 0.4)

  // Over, front (B, α = 0.6) to back (A, α = 0.4), white background:
  //   R = 0.6·0.2 + 0.4·0.4·1.0 + 0.4·0.6·1 = 0.52
  //   G = 0.6·0.4 + 0.4·0.4·0.6 + 0.24      = 0.576
  //   B = 0.6·1.0 + 0.4·0.4·0.2 + 0.24      = 0.872
  const glm::vec3 c = compositeOver(px, glm::vec3(1.0f));
  EXPECT_NEAR(c.r, 0.52f, 1e-5f);
  EXPECT_NEAR(c.g, 0.576f, 1e-5f);
  EXPECT_NEAR(c.b, 0.872f, 1e-5f);

  const ImageRGBA8 image = compositeOver(lists, glm::vec3(1.0f));
  ASSERT_EQ(image.width, 40);
  ASSERT_EQ(image.height, 40);
  // 0.52·255 = 132.6 → 133, 0.576·255 = 146.88 → 147, 0.872·255 = 222.36 → 222.
  EXPECT_EQ(image.at(25, 19)[0], 133);
  EXPECT_EQ(image.at(25, 19)[1], 147);
  EXPECT_EQ(image.at(25, 19)[2], 222);
  EXPECT_EQ(image.at(25, 19)[3], 255);
  // Only A at (−0.55, 0.05), pixel (14, 19): 0.4·(1, 0.6, 0.2) + 0.6·1 = (1, 0.84, 0.68) → (255, 214, 173).
  EXPECT_EQ(image.at(14, 19)[0], 255);
  EXPECT_EQ(image.at(14, 19)[1], 214);
  EXPECT_EQ(image.at(14, 19)[2], 173);
  // Nothing at a corner: the background.
  EXPECT_EQ(image.at(0, 0)[0], 255);
  EXPECT_EQ(image.at(0, 0)[1], 255);
  EXPECT_EQ(image.at(0, 0)[2], 255);
}

TEST(CompositeOver, HandBuiltListsAndBackground) {
  const Fragment front{0.25f, 0x99FF6633u, 1, true};  // (0.2, 0.4, 1.0), α 0.6
  const Fragment back{0.5f, 0x663399FFu, 0, true};    // (1.0, 0.6, 0.2), α 0.4
  const Fragment list[2] = {front, back};
  // Black background: 0.6·(0.2, 0.4, 1) + 0.4·0.4·(1, 0.6, 0.2) = (0.28, 0.336, 0.632).
  const glm::vec3 c = compositeOver(std::span<const Fragment>(list), glm::vec3(0.0f));
  EXPECT_NEAR(c.r, 0.28f, 1e-5f);
  EXPECT_NEAR(c.g, 0.336f, 1e-5f);
  EXPECT_NEAR(c.b, 0.632f, 1e-5f);
  // No fragments: the background itself.
  const glm::vec3 bg = compositeOver(std::span<const Fragment>(), glm::vec3(0.1f, 0.2f, 0.3f));
  EXPECT_FLOAT_EQ(bg.r, 0.1f);
  EXPECT_FLOAT_EQ(bg.g, 0.2f);
  EXPECT_FLOAT_EQ(bg.b, 0.3f);
  // An opaque fragment hides everything behind it: (255, 0, 0, 255) over anything is red.
  const Fragment opaque{0.1f, 0xFF0000FFu, 0, true};
  const Fragment two[2] = {opaque, back};
  const glm::vec3 red = compositeOver(std::span<const Fragment>(two), glm::vec3(1.0f));
  EXPECT_FLOAT_EQ(red.r, 1.0f);
  EXPECT_FLOAT_EQ(red.g, 0.0f);
  EXPECT_FLOAT_EQ(red.b, 0.0f);
}

// The field of view spans the image's shorter side: landscape and square images keep glm's
// vertical field of view exactly; a portrait image of a fitted view still holds the whole bounding
// sphere (every point of it projects inside the image), where a vertical field of view would cut
// its sides off; orthographic alike.
TEST(CameraProjection, FieldOfViewSpansTheShorterSide) {
  Camera c;
  c.eye = {1.0, 2.0, 6.0};
  c.fovyDegrees = 40.0;
  for (const double aspect : {1.0, 1.5}) {
    const glm::dmat4 want = glm::perspective(glm::radians(40.0), aspect, c.nearPlane, c.farPlane);
    const glm::dmat4 got = c.projectionMatrix(aspect);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) EXPECT_DOUBLE_EQ(got[i][j], want[i][j]);
  }
  Bounds b;
  b.extend(glm::dvec3(-3.0, -0.4, -0.5));
  b.extend(glm::dvec3(3.0, 0.4, 0.5));  // long in x, like an engine
  for (const Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    Camera base;
    base.projection = projection;
    const Camera fitted = base.fittedTo(b);
    const double r = b.radius();
    for (const double aspect : {1.0, 0.5, 0.25}) {
      SCOPED_TRACE(aspect);
      const glm::dmat4 m = fitted.projectionMatrix(aspect) * fitted.viewMatrix();
      double reach = 0.0;  // the largest |NDC x| or |NDC y| over the sphere's outline points
      for (int i = 0; i < 64; ++i) {
        const double t = 2.0 * 3.14159265358979 * i / 64;
        for (const glm::dvec3 d :
             {glm::dvec3(std::cos(t), std::sin(t), 0.0), glm::dvec3(std::cos(t), 0.0, std::sin(t))}) {
          const glm::dvec4 p = m * glm::dvec4(b.center() + r * d, 1.0);
          reach = std::max({reach, std::abs(p.x / p.w), std::abs(p.y / p.w)});
        }
      }
      EXPECT_LT(reach, 1.0);
      EXPECT_GT(reach, 0.8);  // and the sphere still fills the shorter side
    }
  }
}

TEST(OracleDepth, PerspectivePlanesGiveProjectionFormulaDepth) {
  // Planes perpendicular to the view at eye distances 10 and 13, large enough to fill the view
  // (half-width 10·tan 20°·1.5 = 5.5 and 7.1).
  Scene scene;
  scene.name = "planes";
  addObject(scene, makePlane(20.0, 20.0), glm::dmat4(1.0), {1.0f, 1.0f, 1.0f, 0.5f});
  addObject(scene, makePlane(30.0, 30.0), translate(0.0, 0.0, -3.0), {1.0f, 1.0f, 1.0f, 0.5f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Perspective), 48, 32);
  // OpenGL: z_ndc = (f + n)/(f − n) + 2fn/((f − n)·z_eye), depth = (z_ndc + 1)/2; n = 1, f = 20.
  //   z_eye = −10: z_ndc = 21/19 − 40/190 = 17/19,   depth = 18/19
  //   z_eye = −13: z_ndc = 21/19 − 40/247 = 233/247, depth = 240/247
  const double n = 1.0, f = 20.0;
  const auto depthAt = [&](double zEye) { return 0.5 * ((f + n) / (f - n) + 2.0 * f * n / ((f - n) * zEye)) + 0.5; };
  ASSERT_NEAR(depthAt(-10.0), 18.0 / 19.0, 1e-12);
  ASSERT_NEAR(depthAt(-13.0), 240.0 / 247.0, 1e-12);
  int checked = 0;
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      if (lists.isAmbiguous(x, y)) continue;  // the quads' diagonals
      const auto px = lists.pixel(x, y);
      ASSERT_EQ(px.size(), 2u) << x << "," << y;
      EXPECT_NEAR(px[0].depth, 18.0 / 19.0, 1e-6);
      EXPECT_NEAR(px[1].depth, 240.0 / 247.0, 1e-6);
      // Planes facing the view: the depth does not change across the image.
      EXPECT_NEAR(px[0].depthSlope, 0.0, 1e-9);
      EXPECT_NEAR(px[1].depthSlope, 0.0, 1e-9);
      EXPECT_TRUE(px[0].frontFacing);
      ++checked;
    }
  EXPECT_GT(checked, 48 * 32 / 2);
}

TEST(OracleDepth, GroundPlaneCrossingEyeAndFarPlanes) {
  // A ground plane y = −1 reaching from behind the eye (z = 10) to beyond the far plane: GL clips it
  // at both. A pixel with NDC y = ny < 0 sees the ground at eye depth z_eye = −1/(|ny|·tan 20°); it
  // has one fragment with the projection-formula depth (and its change per pixel, depthSlope) when
  // −20 ≤ z_eye ≤ −1, none otherwise.
  Scene scene;
  scene.name = "ground";
  addObject(scene, makePlane(200.0, 200.0),
            translate(0.0, -1.0, 0.0) * glm::rotate(glm::dmat4(1.0), glm::radians(-90.0), glm::dvec3(1.0, 0.0, 0.0)),
            {1.0f, 1.0f, 1.0f, 0.5f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Perspective), 64, 64);
  const double n = 1.0, f = 20.0;
  const double tanHalfFov = std::tan(20.0 * 3.14159265358979323846 / 180.0);
  int withFragment = 0;
  for (int y = 0; y < 64; ++y) {
    const double ny = (63.0 - y + 0.5) / 32.0 - 1.0;
    const double zEye = ny < 0.0 ? -1.0 / (-ny * tanHalfFov) : -1e300;
    for (int x = 0; x < 64; ++x) {
      if (lists.isAmbiguous(x, y)) continue;  // the far clip line and the quad diagonal
      SCOPED_TRACE(std::to_string(x) + "," + std::to_string(y));
      if (zEye < -f || zEye > -n) {
        EXPECT_EQ(lists.count(x, y), 0u);
        continue;
      }
      ASSERT_EQ(lists.count(x, y), 1u);
      const Fragment& frag = lists.pixel(x, y)[0];
      EXPECT_NEAR(frag.depth, 0.5 * ((f + n) / (f - n) + 2.0 * f * n / ((f - n) * zEye)) + 0.5, 1e-6);
      // depth = const − f·n·tan 20°·|ny|/(f − n) on the ground: affine in ny, which changes by 1/32
      // per pixel, and independent of x.
      EXPECT_NEAR(frag.depthSlope, f * n * tanHalfFov / ((f - n) * 32.0), 1e-7);
      EXPECT_TRUE(frag.frontFacing);  // seen from above
      ++withFragment;
    }
  }
  // Rows 0..31 are sky; z_eye ≥ −20 needs |ny| ≥ 1/(20·tan 20°) = 0.137, i.e. rows ≥ 36.
  EXPECT_GT(withFragment, 64 * 25);
  for (int x = 0; x < 64; ++x) EXPECT_EQ(lists.count(x, 34), 0u);
}

TEST(OracleDepth, MirroredTransformFlipsFacing) {
  // Mirroring x reverses the winding GL sees: the +Z-facing plane becomes a back face.
  Scene scene;
  scene.name = "mirror";
  addObject(scene, makePlane(4.0, 4.0), glm::scale(glm::dmat4(1.0), glm::dvec3(-1.0, 1.0, 1.0)),
            {1.0f, 1.0f, 1.0f, 1.0f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Perspective), 32, 32);
  ASSERT_FALSE(lists.isAmbiguous(10, 12));
  ASSERT_EQ(lists.count(10, 12), 1u);
  EXPECT_FALSE(lists.pixel(10, 12)[0].frontFacing);
  // The same plane turned around (rotated 180° about Y) is a back face too; unrotated it is front.
  scene.objects[0].transform = glm::rotate(glm::dmat4(1.0), glm::radians(180.0), glm::dvec3(0.0, 1.0, 0.0));
  EXPECT_FALSE(castFragments(scene, frontCamera(Projection::Perspective), 32, 32).pixel(10, 12)[0].frontFacing);
  scene.objects[0].transform = glm::dmat4(1.0);
  EXPECT_TRUE(castFragments(scene, frontCamera(Projection::Perspective), 32, 32).pixel(10, 12)[0].frontFacing);
}

// Shading does not depend on a part's scale: at 1e12 the transformed normals were 1e-12 long, under
// the cancelled-normal test, and the oracle drew the sphere flat where the GPU shaded it (bench
// reported RMSE 0.16 for an exact method). Each scale's camera is scaled alike, so every pixel
// sees the same surface point.
TEST(OracleShading, DoesNotDependOnTheScale) {
  const auto colours = [](double scale) {
    Scene scene;
    scene.name = "scaled";
    addObject(scene, makeSphere(1.0), glm::scale(glm::dmat4(1.0), glm::dvec3(scale)), {1.0f, 0.0f, 0.0f, 1.0f});
    Camera camera = frontCamera(Projection::Orthographic, 3.0 * scale);
    camera.eye *= scale;
    camera.nearPlane *= scale;
    camera.farPlane *= scale;
    const FragmentLists lists = castFragments(scene, camera, 32, 32);
    std::vector<std::uint32_t> out;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) out.push_back(lists.count(x, y) > 0 ? lists.pixel(x, y)[0].color : 0u);
    return out;
  };
  const std::vector<std::uint32_t> unit = colours(1.0);
  ASSERT_GT(std::count_if(unit.begin(), unit.end(), [](std::uint32_t c) { return c != 0u; }),
            300);  // a disc of radius 1 in 3 × 3: about 357 pixels
  for (const double scale : {1e-6, 1e6, 1e12, 1e14}) {
    const std::vector<std::uint32_t> scaled = colours(scale);
    int differ = 0;
    for (std::size_t i = 0; i < unit.size(); ++i) {
      const glm::vec4 a = glm::unpackUnorm4x8(unit[i]), b = glm::unpackUnorm4x8(scaled[i]);
      differ += glm::length(a - b) > 2.5f / 255.0f ? 1 : 0;
    }
    EXPECT_LE(differ, 4) << "scale " << scale;  // edge pixels may round the other way
  }
}

// The fit view frames a scene whatever its size: a sphere 1e-11 across was framed as if 1e-9
// (absolute floors on the radius and the far plane) and rendered blank, one of 3e-10 as a speck.
TEST(CameraFit, FramesTinyScenesAsLargeOnes) {
  const auto fragments = [](double scale) {
    Scene scene;
    scene.name = "scaled";
    addObject(scene, makeSphere(1.0), glm::scale(glm::dmat4(1.0), glm::dvec3(scale)), {1.0f, 0.0f, 0.0f, 0.5f});
    return castFragments(scene, scene.fit(frontCamera(Projection::Perspective)), 48, 48).fragments.size();
  };
  const std::size_t unit = fragments(1.0);
  ASSERT_GT(unit, 1000u);
  for (const double scale : {3e-10, 1e-11, 1e-20, 1e20})
    EXPECT_NEAR(static_cast<double>(fragments(scale)), static_cast<double>(unit), 0.01 * unit) << "scale " << scale;
}

TEST(OracleHistogram, HandCountedQuads) {
  // 40×40 px over 4×4 world units; every quad side lies on a pixel boundary (multiples of 0.1) and
  // neither diagonal comes within 0.06 px of a pixel centre, so no pixel is ambiguous.
  //   A: 2 × 1.6 at the origin → x ∈ (−1, 1): columns 10..29, y ∈ (−0.8, 0.8): rows 12..27 → 320 px
  //   B: 1.2 × 1.0 centred (1, 0.5) → columns 24..35, rows 10..19 → 120 px
  //   both: columns 24..29, rows 12..19 → 48 px
  Scene scene;
  scene.name = "histogram";
  addObject(scene, makePlane(2.0, 1.6), glm::dmat4(1.0), {1.0f, 0.0f, 0.0f, 0.5f});
  addObject(scene, makePlane(1.2, 1.0), translate(1.0, 0.5, 0.5), {0.0f, 1.0f, 0.0f, 0.5f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Orthographic, 4.0), 40, 40);
  const std::vector<std::uint64_t> h = depthComplexityHistogram(lists);
  ASSERT_EQ(h.size(), 3u);
  EXPECT_EQ(h[2], 48u);
  EXPECT_EQ(h[1], 320u + 120u - 2u * 48u);
  EXPECT_EQ(h[0], 1600u - 344u - 48u);
  EXPECT_EQ(std::accumulate(h.begin(), h.end(), std::uint64_t{0}), 1600u);
  EXPECT_EQ(lists.maxCount(), 2u);
  for (std::uint8_t f : lists.flags) EXPECT_EQ(f, 0);

  const ImageF n = depthComplexity(lists);
  ASSERT_EQ(n.width, 40);
  ASSERT_EQ(n.height, 40);
  EXPECT_EQ(n.at(25, 15), 2.0f);  // (0.55, 0.45): both
  EXPECT_EQ(n.at(12, 15), 1.0f);  // (−0.75, 0.45): A only
  EXPECT_EQ(n.at(33, 11), 1.0f);  // (1.35, 0.85): B only
  EXPECT_EQ(n.at(5, 5), 0.0f);
}

TEST(OracleEdges, PixelCentreOnQuadEdgeIsFlagged) {
  // A 2.1 × 2.1 quad, 0.1 world units per pixel: its right side x = 1.05 passes through the centres
  // of column 30 ((30.5)/10 − 2 = 1.05), its top side y = 1.05 through those of row 9.
  Scene scene;
  scene.name = "edge";
  addObject(scene, makePlane(2.1, 2.1), glm::dmat4(1.0), {1.0f, 1.0f, 1.0f, 0.5f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Orthographic, 4.0), 40, 40);
  for (int y = 12; y <= 27; ++y) {
    EXPECT_TRUE(lists.isEdge(30, y)) << y;   // on the right side
    EXPECT_FALSE(lists.isEdge(31, y)) << y;  // 1 px outside
    EXPECT_FALSE(lists.isEdge(29, y)) << y;  // 1 px inside
    EXPECT_EQ(lists.count(31, y), 0u);
    EXPECT_EQ(lists.count(29, y), 1u);
  }
  EXPECT_TRUE(lists.isEdge(20, 9));  // (0.05, 1.05): on the top side
  EXPECT_FALSE(lists.isEdge(20, 10));
  // Interior pixels off the diagonal (x + y = 39 in pixels) are clean.
  EXPECT_FALSE(lists.isAmbiguous(25, 15));
  EXPECT_FALSE(lists.isAmbiguous(15, 15));
  // Pixel centres exactly on the diagonal hit both triangles at the same depth: edge and tie.
  EXPECT_TRUE(lists.isEdge(20, 19));
}

TEST(OracleEdges, EpsilonIsAPerpendicularPixelDistance) {
  // Quad side at x = 1.05 + 0.001 (0.01 px right of column 30's centres) and a second one 0.03 px
  // away: with ε = 0.02 px only the first flags column 30.
  Scene scene;
  scene.name = "eps";
  addObject(scene, makePlane(2.1, 2.1), translate(0.001, 0.0, 0.0), {1.0f, 1.0f, 1.0f, 0.5f});
  const Camera camera = frontCamera(Projection::Orthographic, 4.0);
  EXPECT_TRUE(castFragments(scene, camera, 40, 40).isEdge(30, 20));
  scene.objects[0].transform = translate(0.003, 0.0, 0.0);
  const FragmentLists far = castFragments(scene, camera, 40, 40);
  EXPECT_FALSE(far.isEdge(30, 20));
  EXPECT_EQ(far.count(30, 20), 1u);  // the centre is inside now, 0.03 px from the side
}

TEST(OracleEdges, EdgeOnTriangleGivesNoFragments) {
  // A plane seen exactly edge-on (rotated 90° about Y, through the view axis) has zero screen area:
  // GL draws nothing, so the oracle reports no fragments, only edge flags along its line.
  Scene scene;
  scene.name = "edge-on";
  addObject(scene, makePlane(4.0, 4.0), glm::rotate(glm::dmat4(1.0), glm::radians(90.0), glm::dvec3(0.0, 1.0, 0.0)),
            {1.0f, 1.0f, 1.0f, 1.0f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Orthographic, 4.0), 41, 41);
  EXPECT_EQ(lists.offsets.back(), 0u);
  EXPECT_EQ(lists.fragments.size(), 0u);
  EXPECT_TRUE(lists.isEdge(20, 20));  // column 20's centres lie on x = 0
  EXPECT_FALSE(lists.isEdge(19, 20));
}

TEST(OracleDegenerate, ZeroAreaTrianglesAreSkippedAndCoplanarOnesTie) {
  // One mesh: a triangle with a repeated vertex, one with three collinear vertices, and a real
  // 2 × 2 quad at z = 0 (two triangles); a second, identical quad coincides with it (z-fighting).
  Mesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 0}, {0.5f, 0.5f, 0}};
  m.normals.assign(m.positions.size(), glm::vec3(0, 0, 1));
  m.indices = {0, 0, 2, 0, 4, 2, 0, 1, 2, 0, 2, 3};  // degenerate, collinear, then the quad
  Scene scene;
  scene.name = "degenerate";
  addObject(scene, m, glm::dmat4(1.0), {1.0f, 0.0f, 0.0f, 0.5f});
  addObject(scene, makePlane(2.0, 2.0), glm::dmat4(1.0), {0.0f, 1.0f, 0.0f, 0.5f});
  const FragmentLists lists = castFragments(scene, frontCamera(Projection::Orthographic, 4.0), 40, 40);
  // Pixel (25, 15): world (0.55, 0.45), inside the quad, 0.7 px off its diagonal (and off the
  // collinear triangle's line y = x, which must not count as an edge: it has no area).
  const auto px = lists.pixel(25, 15);
  ASSERT_EQ(px.size(), 2u);
  EXPECT_EQ(px[0].depth, px[1].depth);
  EXPECT_EQ(px[0].objectId, 0u);  // equal depth: ordered by object id
  EXPECT_EQ(px[1].objectId, 1u);
  EXPECT_FALSE(lists.isEdge(25, 15));
  EXPECT_TRUE(lists.isAmbiguous(25, 15));  // kDepthTie
  EXPECT_EQ(lists.count(5, 5), 0u);

  // Only zero-area triangles: nothing to render.
  Mesh flat;
  flat.positions = {{0, 0, 0}, {1, 1, 0}, {2, 2, 0}};
  flat.normals.assign(3, glm::vec3(0, 0, 1));
  flat.indices = {0, 1, 2, 0, 0, 1};
  Scene degenerate;
  degenerate.name = "flat";
  addObject(degenerate, flat, glm::dmat4(1.0), {1.0f, 1.0f, 1.0f, 1.0f});
  EXPECT_THROW(castFragments(degenerate, frontCamera(Projection::Orthographic, 4.0), 8, 8), Error);
}

TEST(OracleThreads, ResultDoesNotDependOnThreadCount) {
  const Scene scene = nestedSpheres();
  const Camera camera = frontCamera(Projection::Perspective);
  OracleOptions one;
  one.threads = 1;
  OracleOptions many;
  many.threads = 5;
  const FragmentLists a = castFragments(scene, camera, 50, 37, one);
  const FragmentLists b = castFragments(scene, camera, 50, 37, many);
  ASSERT_EQ(a.offsets, b.offsets);
  ASSERT_EQ(a.flags, b.flags);
  ASSERT_EQ(a.fragments.size(), b.fragments.size());
  for (std::size_t i = 0; i < a.fragments.size(); ++i) {
    EXPECT_EQ(a.fragments[i].depth, b.fragments[i].depth);
    EXPECT_EQ(a.fragments[i].color, b.fragments[i].color);
    EXPECT_EQ(a.fragments[i].objectId, b.fragments[i].objectId);
  }
}

// `mfr info`'s histogram casts counts only: the same n(p) and flags as the full lists, and no
// fragment kept (the memory such lists take is what the option saves).
TEST(OracleCountsOnly, SameCountsAndFlagsWithoutFragments) {
  const Scene scene = nestedSpheres();
  const Camera camera = frontCamera(Projection::Perspective);
  OracleOptions counting;
  counting.countsOnly = true;
  const FragmentLists full = castFragments(scene, camera, 50, 37);
  const FragmentLists counted = castFragments(scene, camera, 50, 37, counting);
  ASSERT_GT(full.fragments.size(), 1000u);
  EXPECT_EQ(counted.offsets, full.offsets);
  EXPECT_EQ(counted.flags, full.flags);
  EXPECT_TRUE(counted.fragments.empty());
  EXPECT_EQ(depthComplexityHistogram(counted), depthComplexityHistogram(full));
}

// A ray exactly through a shared edge or vertex hits one of the triangles there, as GL's
// rasteriser covers such a sample once: with inclusive bounds it hit them all, so a two-triangle
// square counted 2 fragments on its diagonal and a fan every sliver at its hub (a bug hunt).
TEST(Oracle, RaysOnSharedEdgesAndVerticesHitOneTriangle) {
  // The square fills the orthographic view: its diagonal runs through the pixel centres
  // (i + 0.5, i + 0.5), and its corners' neighbours along the border.
  Scene square;
  square.name = "square";
  addObject(square, makePlane(2.0, 2.0), glm::dmat4(1.0), {0.8f, 0.2f, 0.2f, 0.5f});
  const FragmentLists a = castFragments(square, frontCamera(Projection::Orthographic, 2.0), 16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) EXPECT_EQ(a.count(x, y), 1u) << x << "," << y;
  // A fan of 12 triangles whose hub is the centre pixel's centre, and a plane of 4 by 4 quads
  // whose inner vertices are pixel centres, both in perspective and orthographic views.
  Mesh fan;
  fan.positions.push_back({0.0f, 0.0f, 0.0f});
  for (int i = 0; i < 12; ++i) {
    const double t = 2.0 * 3.14159265358979323846 * i / 12;
    fan.positions.push_back({static_cast<float>(std::cos(t)), static_cast<float>(std::sin(t)), 0.0f});
  }
  for (std::uint32_t i = 0; i < 12; ++i) fan.indices.insert(fan.indices.end(), {0u, 1u + i, 1u + (i + 1) % 12});
  Scene fans;
  fans.name = "fan";
  addObject(fans, fan, glm::dmat4(1.0), {0.2f, 0.2f, 0.8f, 0.5f});
  for (const Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    const FragmentLists f = castFragments(fans, frontCamera(projection, 8.0), 15, 15);
    EXPECT_EQ(f.count(7, 7), 1u);
    EXPECT_EQ(f.maxCount(), 1u);
  }
  Mesh grid;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) grid.positions.push_back({i * 0.5f - 1.0f, j * 0.5f - 1.0f, 0.0f});
  for (std::uint32_t j = 0; j < 4; ++j)
    for (std::uint32_t i = 0; i < 4; ++i) {
      const std::uint32_t c = j * 5 + i;
      grid.indices.insert(grid.indices.end(), {c, c + 1, c + 6, c, c + 6, c + 5});
    }
  Scene quads;
  quads.name = "quads";
  addObject(quads, grid, glm::dmat4(1.0), {0.2f, 0.8f, 0.2f, 0.5f});
  // 15 pixels over 1.875 units: centres at −0.875 + 0.125·i, so the inner vertices and grid lines
  // (−0.5, 0, 0.5) lie on the centres of pixels 3, 7 and 11.
  Camera camera = frontCamera(Projection::Orthographic, 2.0 - 0.125);
  const FragmentLists g = castFragments(quads, camera, 15, 15);
  EXPECT_EQ(g.maxCount(), 1u);
  std::size_t covered = 0;
  for (int y = 0; y < 15; ++y)
    for (int x = 0; x < 15; ++x) covered += g.count(x, y);
  EXPECT_EQ(covered, 15u * 15u);
}

// The broad phase bins each triangle to the pixels near its window polygon; testing every
// triangle against every ray must give the same lists, bit for bit, and the same flags. The
// scenes are the cases a bin could miss: a fan of slivers (each a fraction of a pixel wide),
// triangles reaching behind the eye and past the far plane, a camera inside nested spheres,
// quads lying in the near and far planes, edge-on triangles, a random soup with huge triangles,
// a 170° field of view, an orthographic view, a region of the image, and rays that stray from
// their pixel centres.
TEST(OracleBroadPhase, BinsGiveTheListsOfTestingEveryTriangle) {
  const auto expectSameLists = [](const FragmentLists& a, const FragmentLists& b) {
    ASSERT_EQ(a.offsets, b.offsets);
    ASSERT_EQ(a.flags, b.flags);
    ASSERT_EQ(a.fragments.size(), b.fragments.size());
    for (std::size_t i = 0; i < a.fragments.size(); ++i) {
      SCOPED_TRACE("fragment " + std::to_string(i));
      ASSERT_EQ(a.fragments[i].depth, b.fragments[i].depth);
      ASSERT_EQ(a.fragments[i].color, b.fragments[i].color);
      ASSERT_EQ(a.fragments[i].objectId, b.fragments[i].objectId);
      ASSERT_EQ(a.fragments[i].frontFacing, b.fragments[i].frontFacing);
      ASSERT_EQ(a.fragments[i].depthSlope, b.fragments[i].depthSlope);
    }
  };
  const auto check = [&](const std::string& what, const Scene& scene, const Camera& camera, int width, int height,
                         PixelRect region = {}) {
    SCOPED_TRACE(what);
    OracleOptions binned;
    binned.region = region;
    OracleOptions everyTriangle = binned;
    everyTriangle.everyTriangleACandidate = true;
    const FragmentLists a = castFragments(scene, camera, width, height, binned);
    const FragmentLists b = castFragments(scene, camera, width, height, everyTriangle);
    expectSameLists(a, b);
    return a.fragments.size();
  };

  // Two fans of 3,000 slivers about their hubs, one tilted, as a CAD tessellator writes a disc.
  Mesh fan;
  const int spokes = 3000;
  fan.positions.push_back({0.0f, 0.0f, 0.0f});
  for (int i = 0; i < spokes; ++i) {
    const double a = 2.0 * 3.14159265358979323846 * i / spokes;
    fan.positions.push_back({static_cast<float>(3.0 * std::cos(a)), static_cast<float>(3.0 * std::sin(a)), 0.0f});
  }
  for (int i = 0; i < spokes; ++i)
    fan.indices.insert(fan.indices.end(),
                       {0u, 1u + static_cast<std::uint32_t>(i), 1u + static_cast<std::uint32_t>((i + 1) % spokes)});
  fan.normals.assign(fan.positions.size(), glm::vec3(0, 0, 1));
  Scene fans;
  fans.name = "fans";
  addObject(fans, fan, translate(0.4, -0.3, 0.0), {0.8f, 0.2f, 0.2f, 0.5f});
  addObject(fans, fan, glm::rotate(glm::dmat4(1.0), glm::radians(70.0), glm::dvec3(1.0, 0.2, 0.0)),
            {0.2f, 0.2f, 0.8f, 0.5f});
  // (Over 2,000 before the watertight tie rule: a ray through a hub hit its 3,000 slivers.)
  EXPECT_GT(check("fans, perspective", fans, frontCamera(Projection::Perspective), 61, 47), 1200u);
  EXPECT_GT(check("fans, orthographic", fans, frontCamera(Projection::Orthographic), 61, 47), 1200u);
  EXPECT_GT(check("fans, a region", fans, frontCamera(Projection::Perspective), 61, 47, PixelRect{20, 10, 17, 9}),
            100u);

  // A ground plane from behind the eye to past the far plane; quads in the near plane (z = 9) and
  // the far one (z = −10) of the front camera; an edge-on plane.
  Scene planes;
  planes.name = "planes";
  addObject(planes, makePlane(200.0, 200.0),
            translate(0.0, -1.0, 0.0) * glm::rotate(glm::dmat4(1.0), glm::radians(-90.0), glm::dvec3(1.0, 0.0, 0.0)),
            {1.0f, 1.0f, 1.0f, 0.5f});
  addObject(planes, makePlane(0.3, 0.3), translate(0.05, 0.1, 9.0), {1.0f, 0.0f, 0.0f, 0.5f});
  addObject(planes, makePlane(12.0, 12.0), translate(0.0, 2.0, -10.0), {0.0f, 1.0f, 0.0f, 0.5f});
  addObject(planes, makePlane(4.0, 4.0), glm::rotate(glm::dmat4(1.0), glm::radians(90.0), glm::dvec3(0.0, 1.0, 0.0)),
            {0.0f, 0.0f, 1.0f, 0.5f});
  EXPECT_GT(check("planes", planes, frontCamera(Projection::Perspective), 64, 64), 1000u);

  // Inside nested spheres: the near plane cuts every one of them.
  Camera inside = frontCamera(Projection::Perspective);
  inside.eye = {0.3, 0.2, 0.5};
  inside.target = {0.0, -0.5, -3.0};
  inside.nearPlane = 0.05;
  inside.farPlane = 4.0;
  EXPECT_GT(check("inside", nestedSpheres(), inside, 48, 40), 1000u);
  Camera wide = inside;
  wide.fovyDegrees = 170.0;
  EXPECT_GT(check("inside, 170 degrees", nestedSpheres(), wide, 40, 48), 1000u);

  // 400 random triangles, a tenth of them a hundred times larger (through the eye, off screen).
  Mesh soup;
  std::uint32_t state = 12345;
  const auto random = [&state](double lo, double hi) {
    state = state * 1664525u + 1013904223u;
    return lo + (hi - lo) * (state >> 8) / 16777216.0;
  };
  for (int t = 0; t < 400; ++t) {
    const double scale = t % 10 == 0 ? 100.0 : 1.0;
    const glm::dvec3 centre(random(-4, 4), random(-4, 4), random(-12, 12));
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 p = centre + scale * glm::dvec3(random(-1, 1), random(-1, 1), random(-1, 1));
      soup.positions.push_back(glm::vec3(p));
      soup.indices.push_back(static_cast<std::uint32_t>(soup.positions.size() - 1));
    }
  }
  soup.normals.assign(soup.positions.size(), glm::vec3(0, 0, 1));
  Scene soupScene;
  soupScene.name = "soup";
  addObject(soupScene, soup, glm::dmat4(1.0), {0.5f, 0.5f, 0.5f, 0.3f});
  EXPECT_GT(check("soup", soupScene, frontCamera(Projection::Perspective), 53, 64), 2000u);
  EXPECT_GT(check("soup, orthographic", soupScene, frontCamera(Projection::Orthographic), 53, 64), 2000u);

  // An eye 3·10⁶ from the origin with a near plane at 10⁻⁹: the rays as cast stray pixels from
  // their centres (a fuzzer's case), so the bins must widen by the measured stray.
  Mesh far;
  far.positions = {{2999999.0f, -0.2f, -0.2f}, {2999999.0f, 0.2f, -0.15f}, {2999999.0f, 0.03f, 0.25f}};
  far.normals.assign(3, glm::vec3(1, 0, 0));
  far.indices = {0, 1, 2};
  Scene farScene;
  farScene.name = "far from the origin";
  addObject(farScene, far, glm::dmat4(1.0), {1.0f, 1.0f, 1.0f, 0.5f});
  Camera closeNear = frontCamera(Projection::Perspective);
  closeNear.eye = {3e6, 0.0, 0.0};
  closeNear.target = {2999999.0, 0.0, 0.0};
  closeNear.nearPlane = 1e-9;
  closeNear.farPlane = 10.0;
  EXPECT_GT(check("near plane 1e-9 at 3e6", farScene, closeNear, 16, 16), 20u);
}

// The oracle keeps the last scene's world triangles between calls; a changed scene must never be
// served the old geometry: moving, hiding or editing a part in place (same Mesh object, same
// sizes) each changes the lists as the geometry says.
TEST(OracleCache, ChangedScenesNeverGetTheLastGeometry) {
  const Camera camera = frontCamera(Projection::Orthographic);  // 8 world units over 64 px
  auto mesh = std::make_shared<Mesh>(makeSphere(1.0));
  Scene scene;
  scene.name = "cache";
  Object o;
  o.name = "ball";
  o.mesh = mesh;
  scene.objects.push_back(o);
  // Pixel (32, 31) looks along x, y ≈ 0.06: front hit at z ≈ r, window depth (10 − z − 1) / 19.
  const auto frontDepth = [&](const Scene& s) {
    const FragmentLists lists = castFragments(s, camera, 64, 64);
    return lists.count(32, 31) == 0 ? -1.0 : static_cast<double>(lists.pixel(32, 31)[0].depth);
  };
  EXPECT_NEAR(frontDepth(scene), 8.0 / 19.0, 0.002);
  EXPECT_NEAR(frontDepth(scene), 8.0 / 19.0, 0.002);  // from the kept tree

  Scene moved = scene;
  moved.objects[0].transform = translate(0.0, 0.0, 2.0);
  EXPECT_NEAR(frontDepth(moved), 6.0 / 19.0, 0.002);

  Scene hidden = scene;
  hidden.objects[0].visible = false;
  addObject(hidden, makeSphere(3.0), glm::dmat4(1.0), {1.0f, 1.0f, 1.0f, 0.5f});
  EXPECT_NEAR(frontDepth(hidden), 6.0 / 19.0, 0.002);
  hidden.objects[0].visible = true;
  hidden.objects[1].visible = false;
  EXPECT_NEAR(frontDepth(hidden), 8.0 / 19.0, 0.002);

  EXPECT_NEAR(frontDepth(scene), 8.0 / 19.0, 0.002);
  for (glm::vec3& p : mesh->positions) p *= 2.0f;  // the same Mesh, edited where it lies
  EXPECT_NEAR(frontDepth(scene), 7.0 / 19.0, 0.002);
}

TEST(OracleErrors, BadSizesAndEmptyScenesThrow) {
  const Scene scene = nestedSpheres();
  const Camera camera = frontCamera(Projection::Perspective);
  EXPECT_THROW(castFragments(scene, camera, 0, 10), Error);
  EXPECT_THROW(castFragments(scene, camera, 10, 0), Error);
  EXPECT_THROW(castFragments(scene, camera, -5, 10), Error);
  EXPECT_THROW(castFragments(scene, camera, 20000, 10), Error);

  Scene empty;
  empty.name = "empty";
  try {
    (void)castFragments(empty, camera, 8, 8);
    FAIL() << "empty scene accepted";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "scene 'empty': nothing to render (no visible triangles)");
  }
  Scene hidden = nestedSpheres();
  for (Object& o : hidden.objects) o.visible = false;
  EXPECT_THROW(castFragments(hidden, camera, 8, 8), Error);
}

// A far plane beyond double's reach of the near one (near 0.01, far 1e30) casts the same fragments
// as one that holds the scene: the far point's w came out 0 and every ray was infinite, so the
// reference was blank while the GPU drew the scene (review 29). Perspective and orthographic.
TEST(Oracle, AFarPlaneBeyondDoublesReachOfTheNearOneCastsTheScene) {
  const Scene scene = makeSampleScene();
  for (const Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    SCOPED_TRACE(projection == Projection::Perspective ? "perspective" : "orthographic");
    Camera camera = frontCamera(projection, 4.0);
    camera.nearPlane = 0.01;
    const FragmentLists held = castFragments(scene, camera, 48, 36);
    camera.farPlane = 1e30;
    const FragmentLists huge = castFragments(scene, camera, 48, 36);
    EXPECT_GT(held.fragments.size(), std::size_t{300});  // measured: 464 and 1,532
    EXPECT_EQ(huge.counts(), held.counts());
  }
}

}  // namespace
}  // namespace mfr
