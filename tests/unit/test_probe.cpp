// The pixel probe (mfr probe, mfrview's Probe dock) and the oracle's pixel regions it rests on:
// eye distances and "over" weights against hand-worked geometry and the "over" formula; a region's
// lists against the whole image's; the pairing of a method's fragments with the exact ones; the
// shares under a method's core/tail split against the hybrid formula and compositeHybrid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "../support/fragments.hpp"
#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/reference/probe.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/primitives.hpp"

namespace mfr {
namespace {

using test::frag;

void addObject(Scene& scene, const std::string& name, Mesh mesh, const glm::dmat4& transform, const glm::vec4& color) {
  Object o;
  o.name = name;
  o.mesh = std::make_shared<const Mesh>(std::move(mesh));
  o.transform = transform;
  o.material.color = color;
  scene.objects.push_back(std::move(o));
}

// Looking down −Z from (0, 0, 10) at the origin; near 1, far 20.
Camera frontCamera(Projection projection) {
  Camera c;
  c.eye = {0.0, 0.0, 10.0};
  c.projection = projection;
  c.orthoHeight = 8.0;
  c.nearPlane = 1.0;
  c.farPlane = 20.0;
  return c;
}

// Two planes facing the camera at z = 0 (red, α ≈ 0.5) and z = −2 (blue, α ≈ 0.25), and a third
// (green, opaque) at z = −5 that covers only x > 0.
Scene planes() {
  Scene s;
  s.name = "planes";
  s.background = {1.0f, 1.0f, 1.0f};
  addObject(s, "red plane", makePlane(20.0, 20.0), glm::dmat4(1.0), {1.0f, 0.0f, 0.0f, 0.5f});
  addObject(s, "blue plane", makePlane(20.0, 20.0), glm::translate(glm::dmat4(1.0), {0.0, 0.0, -2.0}),
            {0.0f, 0.0f, 1.0f, 0.25f});
  addObject(s, "green half", makePlane(10.0, 20.0), glm::translate(glm::dmat4(1.0), {5.0, 0.0, -5.0}),
            {0.0f, 1.0f, 0.0f, 1.0f});
  return s;
}

TEST(PixelProbe, EyeDistancesWeightsAndPartsFromThePlanes) {
  const Scene scene = planes();
  for (const Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    SCOPED_TRACE(projection == Projection::Perspective ? "perspective" : "orthographic");
    const Camera camera = frontCamera(projection);
    // Pixel (40, 21) of 64×48 lies right of the centre (x > 0): all three planes; (20, 30) left: two.
    const PixelProbe right = probePixel(scene, camera, 64, 48, 40, 21);
    ASSERT_EQ(right.fragments.size(), 3u);
    EXPECT_EQ(right.x, 40);
    EXPECT_EQ(right.y, 21);
    EXPECT_FALSE(right.edge);
    // Planes perpendicular to the view axis: eye depth 10 − z whatever the pixel.
    const double eye[3] = {10.0, 12.0, 15.0};
    const std::uint32_t ids[3] = {0, 1, 2};
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(right.fragments[i].eyeDepth, eye[i], 1e-4 * eye[i]) << i;
      EXPECT_EQ(right.fragments[i].fragment.objectId, ids[i]) << i;
      EXPECT_TRUE(right.fragments[i].fragment.frontFacing) << i;
      EXPECT_FALSE(right.fragments[i].held) << i;
    }
    // "over": weight_i = α_i Π_{j<i}(1 − α_j) with the stored 8-bit alphas 128, 64, 255.
    const double a0 = 128.0 / 255.0, a1 = 64.0 / 255.0;
    EXPECT_NEAR(right.fragments[0].weight, a0, 1e-6);
    EXPECT_NEAR(right.fragments[1].weight, (1.0 - a0) * a1, 1e-6);
    EXPECT_NEAR(right.fragments[2].weight, (1.0 - a0) * (1.0 - a1), 1e-6);
    EXPECT_NEAR(right.transmittance, 0.0, 1e-9);

    const PixelProbe left = probePixel(scene, camera, 64, 48, 20, 30);
    ASSERT_EQ(left.fragments.size(), 2u);
    EXPECT_NEAR(left.transmittance, (1.0 - a0) * (1.0 - a1), 1e-6);
    // The probe's colour is the whole image's "over" at that pixel.
    const FragmentLists all = castFragments(scene, camera, 64, 48);
    const glm::vec3 expected = compositeOver(all.pixel(20, 30), scene.background);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(left.exactColor[c], expected[c], 1e-6);
    EXPECT_FALSE(left.captured);
  }
}

TEST(PixelProbe, OutsideTheImageIsRefused) {
  const Scene scene = planes();
  const Camera camera = frontCamera(Projection::Perspective);
  for (const auto& [x, y] : {std::pair{64, 0}, std::pair{0, 48}, std::pair{-1, 3}, std::pair{3, -1}}) {
    try {
      (void)probePixel(scene, camera, 64, 48, x, y);
      ADD_FAILURE() << "(" << x << ", " << y << ") accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("not inside the 64x48 image"), std::string::npos) << e.what();
    }
  }
}

TEST(OracleRegion, ListsInsideEqualTheWholeImageAndOutsideAreEmpty) {
  Scene scene;
  scene.name = "spheres";
  for (double r : {1.0, 2.0, 3.0}) addObject(scene, "sphere", makeSphere(r), glm::dmat4(1.0), {0.5f, 0.5f, 0.5f, 0.3f});
  const Camera camera = frontCamera(Projection::Perspective);
  const FragmentLists all = castFragments(scene, camera, 64, 64);
  OracleOptions options;
  options.region = {10, 20, 30, 17};
  const FragmentLists part = castFragments(scene, camera, 64, 64, options);
  std::size_t inside = 0, fragments = 0, edges = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      if (!options.region.contains(x, y)) {
        EXPECT_EQ(part.count(x, y), 0u) << x << "," << y;
        EXPECT_EQ(part.flags[part.index(x, y)], 0) << x << "," << y;
        continue;
      }
      ++inside;
      ASSERT_EQ(part.count(x, y), all.count(x, y)) << x << "," << y;
      EXPECT_EQ(part.flags[part.index(x, y)], all.flags[all.index(x, y)]) << x << "," << y;
      edges += part.isEdge(x, y) ? 1 : 0;
      for (std::size_t i = 0; i < part.count(x, y); ++i) {
        EXPECT_EQ(part.pixel(x, y)[i].depth, all.pixel(x, y)[i].depth);
        EXPECT_EQ(part.pixel(x, y)[i].color, all.pixel(x, y)[i].color);
        EXPECT_EQ(part.pixel(x, y)[i].objectId, all.pixel(x, y)[i].objectId);
        ++fragments;
      }
    }
  EXPECT_EQ(inside, 30u * 17u);
  EXPECT_GT(fragments, 1000u);  // the region crosses the spheres
  EXPECT_GT(edges, 0u);         // and some of their triangle edges

  for (const PixelRect bad : {PixelRect{60, 0, 5, 1}, PixelRect{0, 60, 1, 5}, PixelRect{-1, 0, 2, 2}}) {
    options.region = bad;
    EXPECT_THROW((void)castFragments(scene, camera, 64, 64, options), Error);
  }
}

TEST(PixelProbe, MatchCapturePairsByDepthAndCountsStrangers) {
  PixelProbe probe;
  for (const Fragment& f : {frag(0.25f, 255, 0, 0, 128), frag(0.5f, 0, 255, 0, 128), frag(0.5f, 0, 0, 255, 128),
                            frag(0.75f, 9, 9, 9, 255)}) {
    ProbeFragment p;
    p.fragment = f;
    probe.fragments.push_back(p);
  }
  // A k = 2 buffer: the nearest fragment and the blue one of the two tied at 0.5 (its colour
  // decides), plus one fragment at a depth where the oracle has none.
  const Fragment held[3] = {frag(0.25f + 2e-6f, 255, 0, 0, 128), frag(0.5f, 0, 0, 254, 128), frag(0.6f, 1, 2, 3, 4)};
  matchCapture(probe, held, 3);
  EXPECT_TRUE(probe.captured);
  EXPECT_EQ(probe.methodCount, 3u);
  EXPECT_EQ(probe.methodFragments.size(), 3u);
  EXPECT_TRUE(probe.fragments[0].held);
  EXPECT_FALSE(probe.fragments[1].held);
  EXPECT_TRUE(probe.fragments[2].held);
  EXPECT_FALSE(probe.fragments[3].held);
  EXPECT_EQ(probe.heldCount(), 2u);
  EXPECT_EQ(probe.unmatched, 1u);
  // Matching again starts afresh; a fragment is paired once.
  const Fragment twice[2] = {frag(0.75f, 9, 9, 9, 255), frag(0.75f, 9, 9, 9, 255)};
  matchCapture(probe, twice, 2);
  EXPECT_EQ(probe.heldCount(), 1u);
  EXPECT_TRUE(probe.fragments[3].held);
  EXPECT_EQ(probe.unmatched, 1u);
}

PixelProbe probeOf(std::initializer_list<Fragment> fragments, std::initializer_list<bool> held) {
  PixelProbe probe;
  auto h = held.begin();
  for (const Fragment& f : fragments) {
    ProbeFragment p;
    p.fragment = f;
    p.held = *h++;
    probe.fragments.push_back(p);
  }
  probe.captured = true;
  return probe;
}

// The paper's formula written out: core (the held fragments, wherever they are in the list) by
// "over", the tail by α-weighted average with τ_tail = (1 − α_avg)^t, then the background.
// The operation zthickness at a pixel: red at eye depth 10, blue at 12, green at 15; slabs of
// 2.9 overlap red and blue (not green): the colour is the whole image's compositeZThickness at the
// pixel, the shares add up with the background's to one and rebuild it; thinner slabs give "over".
TEST(PixelProbe, ZThicknessSplitBlendsTheNearSurfaces) {
  const Scene scene = planes();
  const Camera camera = frontCamera(Projection::Perspective);
  RenderRequest request;
  request.thickness = 2.9;
  PixelProbe probe = probePixel(scene, camera, 64, 48, 40, 21);
  ASSERT_EQ(probe.fragments.size(), 3u);
  splitZThickness(probe, scene, camera, request);
  ASSERT_TRUE(probe.zthickness);
  EXPECT_EQ(probe.thickness, 2.9);
  EXPECT_EQ(probe.zthicknessBlended, 2u);  // red and blue
  const FragmentLists all = castFragments(scene, camera, 64, 48);
  const glm::vec3 expected =
      compositeZThickness(all.pixel(40, 21), glm::vec4(camera.depthToEye()), 2.9f, scene.background);
  double sum = probe.zthicknessBackground;
  glm::dvec3 rebuilt = probe.zthicknessBackground * glm::dvec3(scene.background);
  for (const ProbeFragment& f : probe.fragments) {
    sum += f.zthicknessWeight;
    rebuilt += f.zthicknessWeight * glm::dvec3(glm::unpackUnorm4x8(f.fragment.color));
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(probe.zthicknessColor[c], expected[c], 1e-6) << c;
    EXPECT_NEAR(rebuilt[c], expected[c], 1e-5) << c;
  }
  EXPECT_NEAR(sum, 1.0, 1e-6);
  // Blue's slab starts inside red's: blue gets more than under "over" (it is no longer behind all
  // of red), red less.
  EXPECT_LT(probe.fragments[0].zthicknessWeight, probe.fragments[0].weight - 0.002);
  EXPECT_GT(probe.fragments[1].zthicknessWeight, probe.fragments[1].weight + 0.002);
  // Slabs thinner than every gap: the "over" shares (an opaque surface's opacity clamped to
  // MFR_ZTHICK_MAX_ALPHA, so that a slab has a finite extinction).
  request.thickness = 0.5;
  splitZThickness(probe, scene, camera, request);
  EXPECT_EQ(probe.zthicknessBlended, 0u);
  double front = 1.0;
  for (const ProbeFragment& f : probe.fragments) {
    const double alpha = std::min(static_cast<double>(glm::unpackUnorm4x8(f.fragment.color).a), MFR_ZTHICK_MAX_ALPHA);
    EXPECT_NEAR(f.zthicknessWeight, front * alpha, 1e-5);
    front *= 1.0 - alpha;
  }
  // The default: 1 % of the scene's diagonal.
  request.thickness = 0.0;
  splitZThickness(probe, scene, camera, request);
  EXPECT_DOUBLE_EQ(probe.thickness, zThicknessDefault(scene.bounds()));
}

TEST(PixelProbe, HybridSplitFollowsTheFormula) {
  const glm::vec3 background(0.2f, 0.4f, 0.6f);
  PixelProbe probe = probeOf(
      {frag(0.1f, 255, 0, 0, 102), frag(0.2f, 0, 255, 0, 51), frag(0.3f, 0, 0, 255, 153), frag(0.4f, 255, 255, 0, 204)},
      {true, false, true, false});
  splitHybrid(probe, background);
  ASSERT_TRUE(probe.hybrid);
  const double a0 = 102 / 255.0, a1 = 51 / 255.0, a2 = 153 / 255.0, a3 = 204 / 255.0;
  const double coreT = (1 - a0) * (1 - a2);
  const double tailA = 1 - std::pow(1 - (a1 + a3) / 2, 2.0);
  const double w[4] = {a0, coreT * a1 / (a1 + a3) * tailA, (1 - a0) * a2, coreT * a3 / (a1 + a3) * tailA};
  double sum = probe.hybridBackground;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(probe.fragments[i].hybridWeight, w[i], 1e-6) << i;
    sum += probe.fragments[i].hybridWeight;
  }
  EXPECT_NEAR(probe.hybridBackground, coreT * (1 - tailA), 1e-6);
  EXPECT_NEAR(sum, 1.0, 1e-9);
  const glm::dvec3 expected = w[0] * glm::dvec3(1, 0, 0) + w[1] * glm::dvec3(0, 1, 0) + w[2] * glm::dvec3(0, 0, 1) +
                              w[3] * glm::dvec3(1, 1, 0) + coreT * (1 - tailA) * glm::dvec3(background);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(probe.hybridColor[c], expected[c], 1e-6) << c;

  // Held = the nearest k: the colour is compositeHybrid's for that k, for every k; all held is "over".
  const std::vector<Fragment> sorted = {frag(0.1f, 200, 10, 30, 90), frag(0.2f, 20, 220, 40, 160),
                                        frag(0.3f, 60, 70, 250, 30), frag(0.5f, 5, 5, 5, 255)};
  for (std::uint32_t k = 0; k <= 4; ++k) {
    SCOPED_TRACE(k);
    PixelProbe prefix = probeOf({sorted[0], sorted[1], sorted[2], sorted[3]}, {k > 0, k > 1, k > 2, k > 3});
    double over = 1.0;
    for (std::size_t i = 0; i < 4; ++i) {
      prefix.fragments[i].weight = over * (glm::unpackUnorm4x8(sorted[i].color).a);
      over *= 1.0 - glm::unpackUnorm4x8(sorted[i].color).a;
    }
    splitHybrid(prefix, background);
    const glm::vec3 reference = compositeHybrid(sorted, k, background);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(prefix.hybridColor[c], reference[c], 1e-6) << c;
    if (k >= 3) {  // a one-fragment tail composites exactly
      for (std::size_t i = 0; i < 4; ++i)
        EXPECT_NEAR(prefix.fragments[i].hybridWeight, prefix.fragments[i].weight, 1e-6);
    }
  }
}

}  // namespace
}  // namespace mfr
