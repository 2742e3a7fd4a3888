// Operation "volume" on the CPU (compositeVolume, the oracle the GPU is compared with) against
// references that share none of its code: Beer–Lambert closed forms for homogeneous media with
// surfaces in front of, inside and behind them; the optical depth of a linearly varying medium,
// which the midpoint rule integrates exactly whatever the step; and the second-order convergence
// of a quadratic medium. The rays are computed here independently (orthographic: along −z).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr::test {
namespace {

// The box [-1, 1]³ sampled by an n³ grid with values f(x, y, z).
template <class F>
Volume boxVolume(int n, F f) {
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = glm::ivec3(n);
  const double h = 2.0 / (n - 1);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) grid->values.push_back(static_cast<float>(f(-1 + i * h, -1 + j * h, -1 + k * h)));
  Volume v;
  v.name = "box";
  v.grid = grid;
  v.origin = glm::dvec3(-1.0);
  v.spacing = glm::dvec3(h);
  return v;
}

// One colour and opacity for every value in [lo, hi].
TransferFunction uniformTransfer(glm::vec4 color, double unitDistance, double lo = 0.0, double hi = 1.0) {
  TransferFunction tf;
  tf.unitDistance = unitDistance;
  tf.points = {{lo, color}, {hi, color}};
  return tf;
}

// Orthographic camera looking down −z from z = 3; near plane at z = 2.5, far at z = −3.
Camera frontCamera() {
  Camera c;
  c.projection = Projection::Orthographic;
  c.eye = {0.0, 0.0, 3.0};
  c.target = {0.0, 0.0, 0.0};
  c.orthoHeight = 3.0;
  c.nearPlane = 0.5;
  c.farPlane = 6.0;
  return c;
}

// Window depth of world depth z on the front camera (square image).
float windowDepth(const Camera& c, double z) {
  const glm::dvec4 clip = c.projectionMatrix(1.0) * c.viewMatrix() * glm::dvec4(0.0, 0.0, z, 1.0);
  return static_cast<float>(0.5 * clip.z / clip.w + 0.5);
}

Fragment surface(const Camera& c, double z, glm::vec4 color) {
  Fragment f;
  f.depth = windowDepth(c, z);
  f.color = glm::packUnorm4x8(color);
  return f;
}

constexpr int kSize = 33;  // odd: the centre pixel's ray is the z axis
const int kCentre = kSize / 2;

glm::vec3 centrePixel(std::span<const Fragment> sorted, const Volume& v, double step, glm::vec3 background,
                      const std::optional<Bounds>& clip = std::nullopt) {
  const VolumeRaySetup setup = volumeRaySetup(v, frontCamera(), kSize, kSize, step, clip);
  return compositeVolume(sorted, kCentre, kCentre, setup, background);
}

void expectNear(glm::vec3 a, glm::vec3 b, float tolerance) {
  EXPECT_NEAR(a.r, b.r, tolerance);
  EXPECT_NEAR(a.g, b.g, tolerance);
  EXPECT_NEAR(a.b, b.b, tolerance);
}

TEST(VolumeTransfer, TableHoldsColourAndExtinctionOfTheControlPoints) {
  TransferFunction tf;
  tf.unitDistance = 0.5;
  tf.points = {{10.0, {0.0f, 0.0f, 1.0f, 0.0f}}, {20.0, {1.0f, 0.0f, 0.0f, 0.5f}}, {30.0, {1.0f, 1.0f, 1.0f, 1.0f}}};
  const std::vector<glm::vec4> t = tf.table();
  ASSERT_EQ(t.size(), static_cast<std::size_t>(MFR_VOLUME_TF_SIZE));
  EXPECT_NEAR(t.front().a, 0.0f, 1e-7);
  EXPECT_NEAR(t.front().b, 1.0f, 1e-7);
  // The last entry: opacity 1 clamped to MFR_VOLUME_MAX_ALPHA, σ = -ln(1 - α)/unit.
  EXPECT_NEAR(t.back().a, -std::log(1.0 / 1024.0) / 0.5, 1e-4);
  // Entry e sits at 10 + 20·e/255; the one nearest 20 interpolates the middle point's neighbours.
  const int e = 127;  // value 19.96…
  const double v = 10.0 + 20.0 * e / 255.0;
  const double alpha = 0.5 * (v - 10.0) / 10.0;
  EXPECT_NEAR(t[e].a, -std::log(1.0 - alpha) / 0.5, 1e-5);
  EXPECT_NEAR(t[e].r, (v - 10.0) / 10.0, 1e-6);
  EXPECT_NO_THROW(tf.validate("tf"));
  tf.points[1].value = 40.0;
  EXPECT_THROW(tf.validate("tf"), Error);  // not ascending
  tf.points = {{1.0, glm::vec4(0.5f)}, {1.0, glm::vec4(0.5f)}};
  EXPECT_THROW(tf.validate("tf"), Error);  // empty range
  // A step at the first value: below it (entry 0, where values below the range clamp) the first
  // point, above it the second (entry 0 took the second: the range below was drawn clear; a bug
  // hunt). A step at the last value: the last point at the top.
  tf.points = {{0.1, {1.0f, 0.0f, 0.0f, 1.0f}}, {0.1, {0.0f, 1.0f, 0.0f, 0.0f}}, {0.9, {0.0f, 1.0f, 0.0f, 0.0f}}};
  const std::vector<glm::vec4> stepped = tf.table();
  EXPECT_EQ(stepped[0].r, 1.0f);
  EXPECT_GT(stepped[0].a, 1.0f);  // opaque
  EXPECT_EQ(stepped[1].g, 1.0f);
  EXPECT_EQ(stepped[1].a, 0.0f);
  tf.points = {{0.1, {0.0f, 1.0f, 0.0f, 0.0f}}, {0.9, {0.0f, 1.0f, 0.0f, 0.0f}}, {0.9, {0.0f, 0.0f, 1.0f, 1.0f}}};
  EXPECT_EQ(tf.table().back().b, 1.0f);
}

TEST(VolumeComposite, HomogeneousMediumIsBeerLambert) {
  const glm::vec4 medium(0.2f, 0.6f, 0.9f, 0.3f);
  Volume v = boxVolume(5, [](double, double, double) { return 0.5; });
  v.transfer = uniformTransfer(medium, 0.25);
  const double sigma = -std::log(1.0 - 0.3) / 0.25;
  const glm::vec3 bg(1.0f, 0.9f, 0.8f);
  // Chord through the box along z: 2 world units.
  const double tr = std::exp(-sigma * 2.0);
  const glm::vec3 expected = glm::vec3(medium) * static_cast<float>(1.0 - tr) + bg * static_cast<float>(tr);
  for (const double step : {0.0, 0.013, 0.7, 5.0}) {  // any step: the medium is constant
    SCOPED_TRACE(step);
    expectNear(centrePixel({}, v, step, bg), expected, 2e-5f);
  }
}

// A clip box crops the medium: the chord along z is what lies inside both boxes.
TEST(VolumeComposite, ClipBoxCropsTheMediumToItsChord) {
  const glm::vec4 medium(0.2f, 0.6f, 0.9f, 0.3f);
  Volume v = boxVolume(5, [](double, double, double) { return 0.5; });
  v.transfer = uniformTransfer(medium, 0.25);
  const double sigma = -std::log(1.0 - 0.3) / 0.25;
  const glm::vec3 bg(1.0f, 0.9f, 0.8f);
  const auto through = [&](double length) {
    const double tr = std::exp(-sigma * length);
    return glm::vec3(medium) * static_cast<float>(1.0 - tr) + bg * static_cast<float>(tr);
  };
  Bounds box;
  box.min = {-5.0, -5.0, -0.25};
  box.max = {5.0, 5.0, 0.5};
  for (const double step : {0.0, 0.013, 0.7}) {
    SCOPED_TRACE(step);
    expectNear(centrePixel({}, v, step, bg, box), through(0.75), 2e-5f);
    // Reaching past the volume on one side: the volume's own face ends the chord there.
    box.min.z = -3.0;
    expectNear(centrePixel({}, v, step, bg, box), through(1.5), 2e-5f);
    box.min.z = -0.25;
  }
  // A box beside the ray: no medium at all.
  Bounds aside;
  aside.min = {0.2, -5.0, -5.0};
  aside.max = {5.0, 5.0, 5.0};
  expectNear(centrePixel({}, v, 0.0, bg, aside), bg, 1e-6f);
}

TEST(VolumeComposite, SurfacesInFrontInsideAndBehindTheMediumAtTheirExactDepths) {
  const glm::vec4 medium(0.9f, 0.3f, 0.1f, 0.4f);
  Volume v = boxVolume(4, [](double, double, double) { return 0.2; });
  v.transfer = uniformTransfer(medium, 1.0);
  const double sigma = -std::log(1.0 - 0.4);
  const glm::vec3 bg(0.0f);
  const Camera cam = frontCamera();
  const glm::vec4 front(0.1f, 0.8f, 0.2f, 0.5f), inside(0.2f, 0.2f, 1.0f, 0.6f), behind(1.0f, 1.0f, 1.0f, 0.7f);
  // Colours after 8-bit packing, as the fragments carry them.
  const glm::vec4 f = glm::unpackUnorm4x8(glm::packUnorm4x8(front));
  const glm::vec4 s = glm::unpackUnorm4x8(glm::packUnorm4x8(inside));
  const glm::vec4 b = glm::unpackUnorm4x8(glm::packUnorm4x8(behind));
  const std::vector<Fragment> sorted{surface(cam, 1.7, front), surface(cam, 0.3, inside), surface(cam, -2.0, behind)};
  // Front surface, 0.7 of medium (z 1 → 0.3), the inner surface, 1.3 of medium, the back one.
  const double t1 = std::exp(-sigma * 0.7), t2 = std::exp(-sigma * 1.3);
  glm::dvec3 c = glm::dvec3(b) * double(b.a);         // behind, over black
  c = glm::dvec3(medium) * (1.0 - t2) + t2 * c;       // back part of the medium
  c = glm::dvec3(s) * double(s.a) + (1.0 - s.a) * c;  // the inner surface
  c = glm::dvec3(medium) * (1.0 - t1) + t1 * c;       // front part of the medium
  c = glm::dvec3(f) * double(f.a) + (1.0 - f.a) * c;  // the front surface
  for (const double step : {0.0, 0.05, 0.31}) {
    SCOPED_TRACE(step);
    expectNear(centrePixel(sorted, v, step, bg), glm::vec3(c), 2e-5f);
  }
}

// The same pixel taken apart for the probe: each surface's and each stretch of medium's share,
// against the closed form above — and the colour, against compositeVolume.
TEST(VolumeComposite, BreakdownGivesEachSurfaceAndStretchItsShare) {
  const glm::vec4 medium(0.9f, 0.3f, 0.1f, 0.4f);
  Volume v = boxVolume(4, [](double, double, double) { return 0.2; });
  v.transfer = uniformTransfer(medium, 1.0);
  const double sigma = -std::log(1.0 - 0.4);
  const glm::vec3 bg(0.2f, 0.3f, 0.4f);
  const Camera cam = frontCamera();
  const glm::vec4 front(0.1f, 0.8f, 0.2f, 0.5f), inside(0.2f, 0.2f, 1.0f, 0.6f), behind(1.0f, 1.0f, 1.0f, 0.7f);
  const double fa = glm::unpackUnorm4x8(glm::packUnorm4x8(front)).a,
               sa = glm::unpackUnorm4x8(glm::packUnorm4x8(inside)).a,
               ba = glm::unpackUnorm4x8(glm::packUnorm4x8(behind)).a;
  const std::vector<Fragment> sorted{surface(cam, 1.7, front), surface(cam, 0.3, inside), surface(cam, -2.0, behind)};
  const double t1 = std::exp(-sigma * 0.7), t2 = std::exp(-sigma * 1.3);
  const double mediumWeight[4] = {0.0, (1 - fa) * (1 - t1), (1 - fa) * t1 * (1 - sa) * (1 - t2), 0.0};
  const double surfaceWeight[3] = {fa, (1 - fa) * t1 * sa, (1 - fa) * t1 * (1 - sa) * t2 * ba};
  const VolumeRaySetup setup = volumeRaySetup(v, cam, kSize, kSize, 0.05);
  const VolumeBreakdown b = compositeVolumeBreakdown(sorted, kCentre, kCentre, setup, bg);
  ASSERT_EQ(b.surfaceWeight.size(), 3u);
  ASSERT_EQ(b.mediumWeight.size(), 4u);
  double sum = b.backgroundWeight;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(b.surfaceWeight[i], surfaceWeight[i], 2e-5) << i;
    sum += b.surfaceWeight[i];
  }
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(b.mediumWeight[i], mediumWeight[i], 2e-5) << i;
    expectNear(b.mediumColor[i], glm::vec3(medium) * static_cast<float>(mediumWeight[i]), 2e-5f);
    sum += b.mediumWeight[i];
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_NEAR(b.backgroundWeight, (1 - fa) * t1 * (1 - sa) * t2 * (1 - ba), 2e-5);
  const glm::vec3 whole = compositeVolume(sorted, kCentre, kCentre, setup, bg);
  expectNear(b.color, whole, 0.0f);
}

// Several volumes (up to MFR_MAX_VOLUMES) marched together. The references are Beer–Lambert closed
// forms for homogeneous media: a mixture of two media has extinction σ_a + σ_b and emits
// (σ_a·c_a + σ_b·c_b)/(σ_a + σ_b) (Max 1995, emission-absorption with several absorbers).
glm::vec3 centrePixel(std::span<const Fragment> sorted, std::span<const Volume> volumes, double step,
                      glm::vec3 background) {
  const VolumeRaySetup setup = volumeRaySetup(volumes, frontCamera(), kSize, kSize, step);
  return compositeVolume(sorted, kCentre, kCentre, setup, background);
}

// A homogeneous volume of colour `medium` (σ from its opacity per unit 1) over the box [-1, 1]³
// moved along z by `dz`.
Volume slabVolume(glm::vec4 medium, double dz, const std::string& name) {
  Volume v = boxVolume(3, [](double, double, double) { return 0.5; });
  v.name = name;
  v.transfer = uniformTransfer(medium, 1.0);
  v.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, dz));
  return v;
}

double sigmaOf(const glm::vec4& medium) {
  return -std::log(1.0 - medium.a);
}

TEST(VolumeComposite, OverlappingVolumesMixTheirMedia) {
  const glm::vec4 a(0.9f, 0.2f, 0.1f, 0.3f), b(0.1f, 0.3f, 0.9f, 0.6f);
  const glm::vec3 bg(0.2f, 0.9f, 0.4f);
  const std::vector<Volume> both{slabVolume(a, 0.0, "a"), slabVolume(b, 0.0, "b")};
  const double sa = sigmaOf(a), sb = sigmaOf(b), tr = std::exp(-(sa + sb) * 2.0);
  const glm::dvec3 emitted = (sa * glm::dvec3(a) + sb * glm::dvec3(b)) / (sa + sb);
  const glm::vec3 expected(emitted * (1.0 - tr) + glm::dvec3(bg) * tr);
  for (const double step : {0.0, 0.07, 0.9}) {
    SCOPED_TRACE(step);
    expectNear(centrePixel({}, both, step, bg), expected, 2e-5f);
  }
  // The order the volumes are listed in changes nothing.
  const std::vector<Volume> swapped{both[1], both[0]};
  expectNear(centrePixel({}, swapped, 0.05, bg), centrePixel({}, both, 0.05, bg), 2e-6f);
  // Two copies of one medium are that medium with twice the extinction.
  const std::vector<Volume> twice{slabVolume(a, 0.0, "a1"), slabVolume(a, 0.0, "a2")};
  const double tr2 = std::exp(-2.0 * sa * 2.0);
  expectNear(centrePixel({}, twice, 0.1, bg),
             glm::vec3(a) * static_cast<float>(1.0 - tr2) + bg * static_cast<float>(tr2), 2e-5f);
}

// Boxes overlapping in part along the ray. The steps (0.3, 0.7) do not fall on the boxes' faces:
// the march must cut its intervals there or the closed form is missed.
TEST(VolumeComposite, PartlyOverlappingBoxesAreCutAtTheirFaces) {
  const glm::vec4 a(1.0f, 0.0f, 0.0f, 0.5f), b(0.0f, 0.0f, 1.0f, 0.4f);
  const glm::vec3 bg(0.0f);
  // a: z ∈ [0, 2] (moved +1); b: z ∈ [-1.5, 0.5] (moved −0.5). Front to back along −z:
  // a alone on [0.5, 2] (1.5), both on [0, 0.5] (0.5), b alone on [-1.5, 0] (1.5).
  const std::vector<Volume> volumes{slabVolume(a, 1.0, "a"), slabVolume(b, -0.5, "b")};
  const double sa = sigmaOf(a), sb = sigmaOf(b);
  const double t1 = std::exp(-sa * 1.5), t2 = std::exp(-(sa + sb) * 0.5), t3 = std::exp(-sb * 1.5);
  const glm::dvec3 mix = (sa * glm::dvec3(a) + sb * glm::dvec3(b)) / (sa + sb);
  const glm::dvec3 expected = glm::dvec3(a) * (1.0 - t1) + t1 * (mix * (1.0 - t2) + t2 * (glm::dvec3(b) * (1.0 - t3)));
  for (const double step : {0.3, 0.7, 0.0}) {
    SCOPED_TRACE(step);
    expectNear(centrePixel({}, volumes, step, bg), glm::vec3(expected), 2e-5f);
  }
  // The probe's split by volume: each stretch's share divided as σ_i/σ, adding up to the stretch's.
  const Camera cam = frontCamera();
  const std::vector<Fragment> wall{surface(cam, 0.25, {0.5f, 0.5f, 0.5f, 0.5f})};  // inside the overlap
  const VolumeRaySetup setup = volumeRaySetup(volumes, cam, kSize, kSize, 0.3);
  const VolumeBreakdown d = compositeVolumeBreakdown(wall, kCentre, kCentre, setup, bg);
  ASSERT_EQ(d.mediumWeightByVolume.size(), 2u);
  ASSERT_EQ(d.mediumWeightByVolume[0].size(), 2u);
  const double half = std::exp(-(sa + sb) * 0.25);
  // In front of the wall: a alone over 1.5, then both over 0.25.
  EXPECT_NEAR(d.mediumWeightByVolume[0][0], (1.0 - t1) + t1 * (1.0 - half) * sa / (sa + sb), 2e-5);
  EXPECT_NEAR(d.mediumWeightByVolume[0][1], t1 * (1.0 - half) * sb / (sa + sb), 2e-5);
  for (std::size_t s = 0; s < 2; ++s)
    EXPECT_NEAR(d.mediumWeightByVolume[s][0] + d.mediumWeightByVolume[s][1], d.mediumWeight[s], 1e-6) << s;
  expectNear(d.color, compositeVolume(wall, kCentre, kCentre, setup, bg), 0.0f);
}

// Volumes one behind the other with a gap: each composited in turn, nothing in the gap.
TEST(VolumeComposite, DisjointVolumesComposeFrontToBack) {
  const glm::vec4 a(0.8f, 0.8f, 0.1f, 0.5f), b(0.1f, 0.7f, 0.7f, 0.7f);
  const glm::vec3 bg(1.0f, 1.0f, 1.0f);
  // a on z ∈ [0.2, 2.2] (moved 1.2), b on [-3.2, -1.2] (moved −2.2), listed back first; the far
  // plane at z = −3 ends b's chord at 1.8.
  const std::vector<Volume> volumes{slabVolume(b, -2.2, "b"), slabVolume(a, 1.2, "a")};
  const double ta = std::exp(-sigmaOf(a) * 2.0), tb = std::exp(-sigmaOf(b) * 1.8);  // far plane at z = −3
  const glm::dvec3 expected = glm::dvec3(a) * (1.0 - ta) + ta * (glm::dvec3(b) * (1.0 - tb) + tb * glm::dvec3(bg));
  for (const double step : {0.0, 0.11}) {
    SCOPED_TRACE(step);
    expectNear(centrePixel({}, volumes, step, bg), glm::vec3(expected), 2e-5f);
  }
}

TEST(VolumeComposite, AtMostMaxVolumesAreMarched) {
  std::vector<Volume> volumes;
  for (int i = 0; i <= MFR_MAX_VOLUMES; ++i) volumes.push_back(slabVolume(glm::vec4(0.5f), 0.0, std::to_string(i)));
  EXPECT_THROW(volumeRaySetup(volumes, frontCamera(), kSize, kSize, 0.0), Error);
  volumes.pop_back();
  EXPECT_NO_THROW(volumeRaySetup(volumes, frontCamera(), kSize, kSize, 0.0));
  EXPECT_THROW(volumeRaySetup(std::span<const Volume>(), frontCamera(), kSize, kSize, 0.0), Error);
}

// σ linear in z: the midpoint rule integrates it exactly whatever the step, so the colour of a
// white medium over black is 1 - e^(-τ) with τ the closed-form integral.
TEST(VolumeComposite, LinearMediumHasTheClosedFormOpticalDepth) {
  Volume v = boxVolume(9, [](double, double, double z) { return 0.5 * (z + 1.0); });  // 0 at z = −1, 1 at z = 1
  // Control points with σ(s) = 3s at every table entry: opacity 1 - e^(-3s·unit).
  v.transfer.unitDistance = 0.5;
  for (int e = 0; e < MFR_VOLUME_TF_SIZE; ++e) {
    const double s = e / double(MFR_VOLUME_TF_SIZE - 1);
    v.transfer.points.push_back({s, {1.0f, 1.0f, 1.0f, static_cast<float>(1.0 - std::exp(-3.0 * s * 0.5))}});
  }
  const Camera cam = frontCamera();
  // τ over the whole chord: ∫_{-1}^{1} 3·(z + 1)/2 dz = 3.
  for (const double step : {0.0, 0.037, 0.4, 1.3}) {
    SCOPED_TRACE(step);
    expectNear(centrePixel({}, v, step, glm::vec3(0.0f)), glm::vec3(static_cast<float>(1.0 - std::exp(-3.0))), 2e-5f);
    // An opaque black surface at z = 0.2 cuts the chord: τ = ∫_{0.2}^{1} 1.5(z + 1) dz = 1.5·(2 - 0.72)
    const std::vector<Fragment> wall{surface(cam, 0.2, {0.0f, 0.0f, 0.0f, 1.0f})};
    const double tau = 1.5 * ((0.5 * 1.0 + 1.0) - (0.5 * 0.04 + 0.2));
    expectNear(centrePixel(wall, v, step, glm::vec3(1.0f)), glm::vec3(static_cast<float>(1.0 - std::exp(-tau))), 2e-5f);
  }
}

// σ quadratic in z: the midpoint rule's error is O(step²), so halving the step divides the error by
// about 4 (the closed-form optical depth of ∫ 2·((z+1)/2)² dz over [-1, 1] is 4/3).
TEST(VolumeComposite, QuadraticMediumConvergesAtSecondOrder) {
  Volume v = boxVolume(3, [](double, double, double z) { return 0.5 * (z + 1.0); });
  v.transfer.unitDistance = 1.0;
  for (int e = 0; e < MFR_VOLUME_TF_SIZE; ++e) {
    const double s = e / double(MFR_VOLUME_TF_SIZE - 1);
    v.transfer.points.push_back({s, {1.0f, 1.0f, 1.0f, static_cast<float>(1.0 - std::exp(-2.0 * s * s))}});
  }
  const double exact = 1.0 - std::exp(-4.0 / 3.0);
  double previous = 0.0;
  for (const double step : {0.5, 0.25, 0.125}) {
    const double error = std::abs(centrePixel({}, v, step, glm::vec3(0.0f)).r - exact);
    if (previous > 0.0) {
      EXPECT_GT(previous / error, 3.0) << "step " << step;
      EXPECT_LT(previous / error, 5.0) << "step " << step;
    }
    previous = error;
  }
  EXPECT_LT(previous, 1e-3);
}

// Outside the box's projection a ray meets no medium; a step far below the chord / MFR_VOLUME_MAX_STEPS
// is lengthened (the loop stays bounded) and the result still converged; a dense medium stops the
// march once nothing shows through.
TEST(VolumeComposite, MissesTinyStepsAndOpaqueMedia) {
  const glm::vec4 medium(0.5f, 0.5f, 0.5f, 0.2f);
  Volume v = boxVolume(5, [](double, double, double) { return 0.5; });
  v.transfer = uniformTransfer(medium, 1.0);
  const glm::vec3 bg(0.25f, 0.5f, 0.75f);
  const VolumeRaySetup setup = volumeRaySetup(v, frontCamera(), kSize, kSize, 0.0);
  expectNear(compositeVolume({}, 0, 0, setup, bg), bg, 0.0f);  // corner pixel: outside the box
  const double tr = std::exp(std::log(0.8) * 2.0);
  const glm::vec3 expected = glm::vec3(medium) * static_cast<float>(1.0 - tr) + bg * static_cast<float>(tr);
  expectNear(centrePixel({}, v, 1e-9, bg), expected, 2e-5f);
  v.transfer = uniformTransfer({0.3f, 0.6f, 0.9f, 1.0f}, 0.001);
  const std::vector<Fragment> hidden{surface(frontCamera(), -0.5, {1.0f, 0.0f, 0.0f, 1.0f})};
  expectNear(centrePixel(hidden, v, 0.0, bg), glm::vec3(0.3f, 0.6f, 0.9f), 1e-3f);
}

// Shaded volumes: a medium of one colour whose scalar field is linear — its gradient, and so the
// shading factor mix(1, ambient + diffuse·|n·v|, w), is the same at every sample of the centre
// ray — must be the homogeneous closed form with its emission scaled by that factor.
TEST(VolumeShading, LinearFieldsScaleTheEmissionByTheirLighting) {
  const glm::vec4 medium(0.2f, 0.6f, 0.9f, 0.3f);
  const glm::vec3 bg(1.0f, 0.9f, 0.8f);
  const double unit = 0.25, sigma = -std::log(1.0 - 0.3) / unit, chord = 2.0;
  const double tr = std::exp(-sigma * chord);
  const auto expected = [&](double factor) {
    return glm::vec3(medium) * static_cast<float>(factor * (1.0 - tr)) + bg * static_cast<float>(tr);
  };
  const int n = 9;
  const double h = 2.0 / (n - 1);
  // w = g/(g + EDGE·range): the gradient per grid cell (h for a unit slope) against the range 2.
  const double w = h / (h + MFR_VOLUME_SHADE_EDGE * 2.0);
  const auto shaded = [&](auto field, const glm::dmat4& transform) {
    Volume v = boxVolume(n, field);
    v.transform = transform;
    v.transfer = uniformTransfer(medium, unit, -1.0, 1.0);
    v.shading = true;
    return v;
  };
  const auto lit = [&](double facing) { return (1.0 - w) + w * (MFR_VOLUME_AMBIENT + MFR_VOLUME_DIFFUSE * facing); };
  // Gradient across the ray: only the ambient term lights it.
  expectNear(centrePixel({}, shaded([](double, double y, double) { return y; }, glm::dmat4(1.0)), 0.0, bg),
             expected(lit(0.0)), 2e-5f);
  // Gradient along the ray: fully lit, ambient + diffuse = 1, the unshaded image.
  expectNear(centrePixel({}, shaded([](double, double, double z) { return z; }, glm::dmat4(1.0)), 0.0, bg),
             expected(1.0), 2e-5f);
  // A constant field has no gradient: unshaded.
  expectNear(centrePixel({}, shaded([](double, double, double) { return 0.25; }, glm::dmat4(1.0)), 0.0, bg),
             expected(1.0), 2e-5f);
  // Sheared placement y_world = y + z/2 (z unchanged, so the chord is still 2): the field y is
  // y_world − z_world/2 in the world, gradient (0, 1, −1/2), |n·v| = 0.5/√1.25. Normals must be
  // carried to the world by the inverse transpose of the placement, not by the inverse.
  glm::dmat4 shear(1.0);
  shear[2][1] = 0.5;  // column z, row y
  expectNear(centrePixel({}, shaded([](double, double y, double) { return y; }, shear), 0.0, bg),
             expected(lit(0.5 / std::sqrt(1.25))), 2e-5f);
  // Shading off: the same field is the unshaded closed form.
  Volume plain = shaded([](double, double y, double) { return y; }, glm::dmat4(1.0));
  plain.shading = false;
  expectNear(centrePixel({}, plain, 0.0, bg), expected(1.0), 2e-5f);
}

TEST(VolumeModel, BoundsStepAndValidation) {
  Volume v = boxVolume(5, [](double x, double, double) { return x; });
  v.transfer = uniformTransfer(glm::vec4(0.5f), 1.0);
  EXPECT_NEAR(v.bounds().min.x, -1.0, 1e-12);
  EXPECT_NEAR(v.bounds().max.z, 1.0, 1e-12);
  EXPECT_NEAR(v.defaultStep(), 0.25, 1e-12);
  EXPECT_NEAR(v.grid->sample({1.5f, 0.0f, 0.0f}), -0.25f, 1e-6f);  // trilinear between x = -0.5 and 0
  EXPECT_NEAR(v.grid->sample({-3.0f, 9.0f, 0.0f}), -1.0f, 1e-6f);  // clamped
  EXPECT_NO_THROW(v.validate());
  Volume bad = v;
  bad.spacing.y = 0.0;
  EXPECT_THROW(bad.validate(), Error);
  auto flat = std::make_shared<VolumeGrid>(*v.grid);
  flat->dims.z = 1;
  bad = v;
  bad.grid = flat;
  EXPECT_THROW(bad.validate(), Error);
  auto nan = std::make_shared<VolumeGrid>(*v.grid);
  nan->values[7] = std::nanf("");
  bad = v;
  bad.grid = nan;
  EXPECT_THROW(bad.validate(), Error);
  auto huge = std::make_shared<VolumeGrid>();
  huge->dims = {2048, 2048, 300};  // 1.26·10⁹ points: refused before the (empty) values are looked at
  bad = v;
  bad.grid = huge;
  try {
    bad.validate();
    ADD_FAILURE() << "a grid of more than 2^30 points was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2^30"), std::string::npos) << e.what();
  }
  EXPECT_THROW(transferPreset("rainbow", 0, 1, 1), Error);
  for (const std::string& name : transferPresetNames()) EXPECT_NO_THROW(transferPreset(name, 0, 1, 1).validate(name));
}

}  // namespace
}  // namespace mfr::test
