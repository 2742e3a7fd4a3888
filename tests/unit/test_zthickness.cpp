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
