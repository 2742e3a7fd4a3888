// Z-thickness blending (Kim & Kye, CGF 40(7) 2021) on hand-made lists, against references that do
// not share its code: "over" for slabs further apart than the thickness, the closed form of
// coincident slabs, and a brute-force midpoint integration of the same continuous medium (each
// fragment a slab [z, z + τ] of extinction σ = -ln(1 - α)/τ and emission σ·rgb).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/gtc/packing.hpp>

#include "common/bindings.h"
#include "fragments.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/render.hpp"

namespace {

using mfr::test::frag;

// Window depth = eye depth: z = -(-0.5·ndc - 0.5)/1 = depth.
const glm::vec4 kIdentityDepth(-0.5f, -0.5f, 0.0f, 1.0f);
const glm::vec3 kWhite(1.0f);

double sigmaOf(const mfr::Fragment& f, double tau) {
  const double a = std::min(static_cast<double>(glm::unpackUnorm4x8(f.color).a), MFR_ZTHICK_MAX_ALPHA);
  return -std::log(1.0 - a) / tau;
}

// The continuous medium integrated by the midpoint rule, with the open slabs found by brute force.
glm::dvec3 integrateByBruteForce(const std::vector<mfr::Fragment>& list, double tau, const glm::dvec3& background,
                                 int steps) {
  double lo = 1e30, hi = -1e30;
  for (const mfr::Fragment& f : list) {
    lo = std::min(lo, static_cast<double>(f.depth));
    hi = std::max(hi, static_cast<double>(f.depth) + tau);
  }
  const double dz = (hi - lo) / steps;
  glm::dvec3 colour(0.0);
  double transmittance = 1.0;
  for (int s = 0; s < steps; ++s) {
    const double z = lo + (s + 0.5) * dz;
    double sigma = 0.0;
    glm::dvec3 emission(0.0);
    for (const mfr::Fragment& f : list)
      if (z >= f.depth && z < f.depth + tau) {
        const double si = sigmaOf(f, tau);
        sigma += si;
        emission += si * glm::dvec3(glm::unpackUnorm4x8(f.color));
      }
    colour += transmittance * emission * dz;
    transmittance *= std::exp(-sigma * dz);
  }
  return colour + transmittance * background;
}

void expectNear(const glm::vec3& got, const glm::dvec3& want, double tolerance) {
  EXPECT_NEAR(got.r, want.r, tolerance);
  EXPECT_NEAR(got.g, want.g, tolerance);
  EXPECT_NEAR(got.b, want.b, tolerance);
}

TEST(ZThickness, SlabsFurtherApartThanTheThicknessCompositeLikeOver) {
  const std::vector<mfr::Fragment> list{frag(1.0f, 255, 0, 0, 102), frag(1.5f, 0, 255, 0, 51),
                                        frag(2.0f, 0, 0, 255, 153), frag(2.25f, 40, 80, 120, 200)};
  const glm::vec3 over = mfr::compositeOver(list, kWhite);
  // Float rounding of the slab ends (z + τ in float) is the only difference: 1e-4 ≪ 1/255.
  for (float tau : {0.25f, 0.1f, 1e-3f})
    expectNear(mfr::compositeZThickness(list, kIdentityDepth, tau, kWhite), glm::dvec3(over), 1e-4);
  // Thicker than the gaps: no longer "over" (the test can fail).
  const glm::vec3 thick = mfr::compositeZThickness(list, kIdentityDepth, 0.6f, kWhite);
  EXPECT_GT(glm::length(thick - over), 0.01f);
}

TEST(ZThickness, CoincidentSlabsBlendByExtinctionWhateverTheirOrder) {
  const mfr::Fragment red = frag(1.0f, 255, 0, 0, 128), blue = frag(1.0f, 0, 0, 255, 204);
  const double tau = 0.05;
  const double s1 = sigmaOf(red, tau), s2 = sigmaOf(blue, tau);
  const double a1 = 128.0 / 255.0, a2 = 204.0 / 255.0;
  const double alpha = 1.0 - (1.0 - a1) * (1.0 - a2);
  const glm::dvec3 mix = (s1 * glm::dvec3(1, 0, 0) + s2 * glm::dvec3(0, 0, 1)) / (s1 + s2);
  const glm::dvec3 want = alpha * mix + (1.0 - alpha) * glm::dvec3(1.0);
  expectNear(mfr::compositeZThickness(std::vector{red, blue}, kIdentityDepth, static_cast<float>(tau), kWhite), want,
             1e-5);
  expectNear(mfr::compositeZThickness(std::vector{blue, red}, kIdentityDepth, static_cast<float>(tau), kWhite), want,
             1e-5);
  // "over" depends on the order: the z-fighting that z-thickness removes.
  EXPECT_GT(glm::length(mfr::compositeOver(std::vector{red, blue}, kWhite) -
                        mfr::compositeOver(std::vector{blue, red}, kWhite)),
            0.1f);
}

TEST(ZThickness, OpaqueSurfacesReachTheClampedOpacity) {
  const glm::vec3 got = mfr::compositeZThickness(std::vector{frag(3.0f, 0, 0, 0, 255)}, kIdentityDepth, 0.2f, kWhite);
  expectNear(got, glm::dvec3(1.0 - MFR_ZTHICK_MAX_ALPHA), 1e-6);
  // Two coplanar opaque parts (a duplicated CAD part): an even mix, not one of them.
  const glm::vec3 mix = mfr::compositeZThickness(std::vector{frag(3.0f, 255, 0, 0, 255), frag(3.0f, 0, 0, 255, 255)},
                                                 kIdentityDepth, 0.2f, kWhite);
  EXPECT_NEAR(mix.r, 0.5, 2e-3);
  EXPECT_NEAR(mix.b, 0.5, 2e-3);
}

TEST(ZThickness, OverlappingSlabsMatchBruteForceIntegration) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> byte(0, 255);
  std::uniform_real_distribution<float> gap(0.0f, 0.08f);
  const float tau = 0.1f;
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<mfr::Fragment> list;
    float z = 2.0f;
    const int n = 1 + trial;
    for (int i = 0; i < n; ++i) {
      z += (i % 4 == 3) ? 0.0f : gap(rng);  // some exactly coplanar pairs
      list.push_back(frag(z, byte(rng), byte(rng), byte(rng), i % 5 == 4 ? 255 : byte(rng)));
    }
    const glm::dvec3 want = integrateByBruteForce(list, tau, glm::dvec3(1.0), 200000);
    SCOPED_TRACE("fragments " + std::to_string(n));
    expectNear(mfr::compositeZThickness(list, kIdentityDepth, tau, kWhite), want, 2e-3);
  }
}

TEST(ZThickness, AFullWindowMergesCoincidentSlabsExactly) {
  // More coincident slabs than the window holds: merging into the newest open slab is exact here.
  std::vector<mfr::Fragment> list;
  const int n = MFR_ZTHICK_WINDOW + 9;
  for (int i = 0; i < n; ++i) list.push_back(frag(1.0f, i % 2 ? 255 : 0, 0, i % 2 ? 0 : 255, 20));
  const glm::dvec3 want = integrateByBruteForce(list, 0.1, glm::dvec3(1.0), 20000);
  expectNear(mfr::compositeZThickness(list, kIdentityDepth, 0.1f, kWhite), want, 1e-3);
}

// Each fragment's share of the colour by brute force: Σ over midpoint steps of T(z)·σ_i(z)·dz.
std::vector<double> sharesByBruteForce(const std::vector<mfr::Fragment>& list, double tau, int steps,
                                       double* transmittanceOut) {
  double lo = 1e30, hi = -1e30;
  for (const mfr::Fragment& f : list) {
    lo = std::min(lo, static_cast<double>(f.depth));
    hi = std::max(hi, static_cast<double>(f.depth) + tau);
  }
  const double dz = (hi - lo) / steps;
  std::vector<double> shares(list.size(), 0.0);
  double transmittance = 1.0;
  for (int s = 0; s < steps; ++s) {
    const double z = lo + (s + 0.5) * dz;
    double sigma = 0.0;
    for (std::size_t i = 0; i < list.size(); ++i)
      if (z >= list[i].depth && z < list[i].depth + tau) {
        shares[i] += transmittance * sigmaOf(list[i], tau) * dz;
        sigma += sigmaOf(list[i], tau);
      }
    transmittance *= std::exp(-sigma * dz);
  }
  *transmittanceOut = transmittance;
  return shares;
}

// The probe's breakdown: the same colour in the same arithmetic, shares that add up with the
// background's to one and rebuild the colour, the closed form of coincident slabs, "over" for
// slabs apart, and a brute-force integration of each fragment's share.
TEST(ZThickness, TheBreakdownGivesEachFragmentsShare) {
  const glm::vec3 background(0.2f, 0.5f, 0.9f);
  // Coincident: shares α·σ_i/(σ_1 + σ_2) whatever the order.
  const mfr::Fragment red = frag(1.0f, 255, 0, 0, 128), blue = frag(1.0f, 0, 0, 255, 204);
  const double tau = 0.05, s1 = sigmaOf(red, tau), s2 = sigmaOf(blue, tau);
  const double alpha = 1.0 - (1.0 - 128.0 / 255.0) * (1.0 - 204.0 / 255.0);
  for (const auto& pair : {std::vector{red, blue}, std::vector{blue, red}}) {
    const mfr::ZThicknessBreakdown b =
        mfr::compositeZThicknessBreakdown(pair, kIdentityDepth, static_cast<float>(tau), background);
    ASSERT_EQ(b.weights.size(), 2u);
    const bool redFirst = pair[0].color == red.color;
    EXPECT_NEAR(b.weights[redFirst ? 0 : 1], alpha * s1 / (s1 + s2), 1e-5);
    EXPECT_NEAR(b.weights[redFirst ? 1 : 0], alpha * s2 / (s1 + s2), 1e-5);
    EXPECT_NEAR(b.transmittance, 1.0 - alpha, 1e-5);
  }
  // Apart: the "over" weights α_i·Π(1 − α_j).
  const std::vector<mfr::Fragment> apart{frag(1.0f, 255, 0, 0, 102), frag(1.5f, 0, 255, 0, 51),
                                         frag(2.0f, 0, 0, 255, 153)};
  const mfr::ZThicknessBreakdown over = mfr::compositeZThicknessBreakdown(apart, kIdentityDepth, 0.1f, background);
  double front = 1.0;
  for (std::size_t i = 0; i < apart.size(); ++i) {
    const double a = glm::unpackUnorm4x8(apart[i].color).a;
    EXPECT_NEAR(over.weights[i], front * a, 1e-5) << i;
    front *= 1.0 - a;
  }
  // Random overlapping lists (within the window, some coplanar, one transparent): against brute
  // force; the colour is compositeZThickness's bit for bit and rebuilt from the shares.
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::uint32_t> byte(0, 255);
  std::uniform_real_distribution<float> gap(0.0f, 0.08f);
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<mfr::Fragment> list;
    float z = 2.0f;
    for (int i = 0; i < 1 + trial % MFR_ZTHICK_WINDOW; ++i) {
      z += (i % 4 == 3) ? 0.0f : gap(rng);
      list.push_back(frag(z, byte(rng), byte(rng), byte(rng), i == 2 ? 0 : byte(rng)));
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    const mfr::ZThicknessBreakdown b = mfr::compositeZThicknessBreakdown(list, kIdentityDepth, 0.1f, background);
    EXPECT_EQ(b.color, mfr::compositeZThickness(list, kIdentityDepth, 0.1f, background));
    double bruteT = 0.0;
    const std::vector<double> brute = sharesByBruteForce(list, 0.1, 100000, &bruteT);
    glm::dvec3 rebuilt = b.transmittance * glm::dvec3(background);
    double sum = b.transmittance;
    for (std::size_t i = 0; i < list.size(); ++i) {
      EXPECT_NEAR(b.weights[i], brute[i], 2e-3) << i;
      rebuilt += b.weights[i] * glm::dvec3(glm::unpackUnorm4x8(list[i].color));
      sum += b.weights[i];
    }
    if (list.size() > 2) {
      EXPECT_EQ(b.weights[2], 0.0);  // no opacity, no share
    }
    EXPECT_NEAR(b.transmittance, bruteT, 2e-3);
    EXPECT_NEAR(sum, 1.0, 1e-5);
    expectNear(b.color, rebuilt, 1e-5);
  }
  // A full window: fragments merged into the newest slab still get their own shares.
  std::vector<mfr::Fragment> many;
  for (int i = 0; i < MFR_ZTHICK_WINDOW + 5; ++i) many.push_back(frag(1.0f, i % 2 ? 255 : 0, 0, i % 2 ? 0 : 255, 20));
  const mfr::ZThicknessBreakdown merged = mfr::compositeZThicknessBreakdown(many, kIdentityDepth, 0.1f, background);
  double sum = merged.transmittance;
  for (std::size_t i = 0; i < many.size(); ++i) {
    EXPECT_NEAR(merged.weights[i], merged.weights[0], 1e-6) << i;  // equal opacities, one depth: equal shares
    sum += merged.weights[i];
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
}

TEST(ZThickness, DepthToEyeInvertsTheProjection) {
  for (const mfr::Projection projection : {mfr::Projection::Perspective, mfr::Projection::Orthographic}) {
    mfr::Camera camera;
    camera.projection = projection;
    camera.nearPlane = 0.5;
    camera.farPlane = 40.0;
    const glm::dvec4 k = camera.depthToEye();
    const glm::dmat4 p = camera.projectionMatrix(1.7);
    for (const double z : {0.5, 0.51, 3.0, 17.25, 39.9}) {
      const glm::dvec4 clip = p * glm::dvec4(0.3, -0.2, -z, 1.0);
      const double ndc = clip.z / clip.w;
      EXPECT_NEAR(-(k.x * ndc + k.y) / (k.z * ndc + k.w), z, 1e-9 * z);
    }
  }
}

TEST(ZThickness, BadThicknessIsRefused) {
  mfr::FragmentLists lists;
  lists.width = lists.height = 1;
  lists.offsets = {0, 0};
  lists.flags = {0};
  const mfr::Camera camera;
  for (const double t : {0.0, -1.0, std::nan(""), HUGE_VAL})
    EXPECT_THROW((void)mfr::compositeZThickness(lists, camera, t, kWhite), mfr::Error);
  mfr::RenderRequest request;
  mfr::Bounds bounds;
  bounds.extend(glm::dvec3(0.0));
  bounds.extend(glm::dvec3(3.0, 4.0, 0.0));
  EXPECT_DOUBLE_EQ(mfr::zThicknessOf(request, bounds), 0.05);  // 1 % of the diagonal (5)
  request.thickness = 0.3;
  EXPECT_DOUBLE_EQ(mfr::zThicknessOf(request, bounds), 0.3);
  for (const double t : {-0.1, std::nan(""), HUGE_VAL}) {
    request.thickness = t;
    EXPECT_THROW((void)mfr::zThicknessOf(request, bounds), mfr::Error);
  }
}

}  // namespace
