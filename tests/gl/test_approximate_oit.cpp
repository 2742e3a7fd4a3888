// The approximate single-pass OIT methods against the oracle and against their papers' formulas
// evaluated on the oracle's exact fragments:
//   wboit: McGuire & Bavoil, "Weighted Blended Order-Independent Transparency", JCGT 2(2), 2013
//   mboit: Münstermann, Krumpen, Klein, Peters, "Moment-Based Order-Independent Transparency",
//          Proc. ACM CGIT 1(1), 2018
// One layer per pixel: both reproduce "over" exactly (their normalisation makes the single
// fragment's colour exact and the revealage / total transmittance is exact). Several layers: they
// approximate; tests check the paper's own formula (wboit eq. 6; mboit's reconstruction, which for
// two layers has a closed form), a bounded error on the sample, and memory accounting.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

struct Plane {
  double z;
  glm::vec4 color;
  double x = 0.0;  // centre
  double size = 1.2;
  double tiltDegrees = 0.0;  // about the Y axis
};

Scene planeScene(const std::vector<Plane>& planes, const glm::vec3& background) {
  Scene s;
  s.name = "planes";
  s.background = background;
  const auto mesh = std::make_shared<const Mesh>(makePlane(1.0, 1.0));
  for (const Plane& p : planes) {
    Object o;
    o.name = "plane";
    o.mesh = mesh;
    o.material.color = p.color;
    o.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(p.x, 0.0, p.z)) *
                  glm::rotate(glm::dmat4(1.0), glm::radians(p.tiltDegrees), glm::dvec3(0, 1, 0)) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(p.size, p.size, 1.0));
    s.objects.push_back(std::move(o));
  }
  return s;
}

Camera orthoCamera() {
  Camera c;
  c.eye = {0.0, 0.0, 5.0};
  c.target = {0.0, 0.0, 0.0};
  c.projection = Projection::Orthographic;
  c.orthoHeight = 2.0;
  c.nearPlane = 1.0;
  c.farPlane = 10.0;
  return c;
}

Camera perspectiveCamera() {
  Camera c;
  c.eye = {0.15, 0.1, 4.0};
  c.target = {0.0, 0.0, 0.0};
  c.fovyDegrees = 40.0;
  c.nearPlane = 1.0;
  c.farPlane = 10.0;
  return c;
}

RenderOutput renderWith(const Scene& scene, const Camera& camera, const std::string& method,
                        const std::map<std::string, std::string>& params, int w, int h) {
  context();
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = method;
  req.params = params;
  req.width = w;
  req.height = h;
  return gpu.render(camera, req);
}

// Per-pixel model evaluated on the oracle's exact fragment lists, rounded like the oracle.
ImageRGBA8 modelImage(const FragmentLists& lists, const std::function<glm::vec3(std::span<const Fragment>)>& model) {
  ImageRGBA8 image(lists.width, lists.height);
  const auto to8 = [](float c) { return static_cast<std::uint8_t>(std::round(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const glm::vec3 c = model(lists.pixel(x, y));
      std::uint8_t* p = image.at(x, y);
      p[0] = to8(c.r);
      p[1] = to8(c.g);
      p[2] = to8(c.b);
      p[3] = 255;
    }
  return image;
}

// |z_eye| (perspective) or the distance behind the near plane (orthographic: what wboit can
// recover from the view-projection matrix) of a window depth, from the camera in double precision.
double viewDepth(const Camera& c, double windowDepth) {
  const double n = c.nearPlane, f = c.farPlane, ndc = 2.0 * windowDepth - 1.0;
  if (c.projection == Projection::Orthographic) return (ndc + 1.0) * 0.5 * (f - n);
  return 2.0 * f * n / ((f + n) - ndc * (f - n));
}

// McGuire & Bavoil eq. 6 with the weight functions of eqs. 7–10 (clamped as in the paper), or
// w = 1 ("none").
double wboitWeight(const std::string& weight, const Camera& camera, double alpha, double windowDepth) {
  if (weight == "none") return 1.0;
  if (weight == "eq10") return alpha * std::max(1e-2, 3e3 * std::pow(1.0 - windowDepth, 3.0));
  const double z = viewDepth(camera, windowDepth);
  double w = 0.0;
  if (weight == "eq7") w = 10.0 / (1e-5 + std::pow(z / 5.0, 2.0) + std::pow(z / 200.0, 6.0));
  if (weight == "eq8") w = 10.0 / (1e-5 + std::pow(z / 10.0, 3.0) + std::pow(z / 200.0, 6.0));
  if (weight == "eq9") w = 0.03 / (1e-5 + std::pow(z / 200.0, 4.0));
  return alpha * std::clamp(w, 1e-2, 3e3);
}

glm::vec3 wboitPixel(std::span<const Fragment> fragments, const std::string& weight, const Camera& camera,
                     const glm::vec3& background) {
  glm::dvec3 sum(0.0);
  double sumAlpha = 0.0, revealage = 1.0;
  for (const Fragment& f : fragments) {
    const glm::dvec4 c(glm::unpackUnorm4x8(f.color));
    const double w = wboitWeight(weight, camera, c.a, f.depth);
    sum += glm::dvec3(c) * c.a * w;
    sumAlpha += c.a * w;
    revealage *= 1.0 - c.a;
  }
  const glm::dvec3 average = sum / std::max(sumAlpha, 1e-5);
  return glm::vec3(average * (1.0 - revealage) + glm::dvec3(background) * revealage);
}

void expectMatches(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual, int tolerance,
                   double fraction) {
  const ImageComparison ic = compareImages(oracle, expected, actual, tolerance);
  EXPECT_GT(ic.compared, static_cast<std::size_t>(oracle.width * oracle.height) * 7 / 10);
  EXPECT_GE(ic.fraction(), fraction) << (ic.compared - ic.within) << " of " << ic.compared
                                     << " pixels differ by more than " << tolerance << "/255; max " << ic.maxDifference;
}

// ---- Every variant of both methods -------------------------------------------------------------

struct ApproxCase {
  std::string method;
  std::map<std::string, std::string> params;
  std::string label;
  std::uint64_t bytesPerPixel;  // render targets the method allocates
};

class ApproximateOit : public ::testing::TestWithParam<ApproxCase> {};

std::string approxCaseName(const ::testing::TestParamInfo<ApproxCase>& p) {
  return p.param.method + "_" + p.param.label;
}

INSTANTIATE_TEST_SUITE_P(Methods, ApproximateOit,
                         ::testing::Values(ApproxCase{"wboit", {}, "default", 9},
                                           ApproxCase{"wboit", {{"weight", "eq8"}}, "eq8", 9},
                                           ApproxCase{"wboit", {{"weight", "eq9"}}, "eq9", 9},
                                           ApproxCase{"wboit", {{"weight", "eq10"}}, "eq10", 9},
                                           ApproxCase{"wboit", {{"weight", "none"}}, "none", 9},
                                           ApproxCase{"wboit", {{"revealage", "r16f"}}, "r16f", 10},
                                           ApproxCase{"mboit", {}, "default", 28},
                                           ApproxCase{"mboit", {{"moments", "6"}}, "moments6", 36},
                                           ApproxCase{"mboit", {{"warp", "linear"}}, "linear", 28}),
                         approxCaseName);

// One transparent layer per pixel (two tilted planes side by side, no overlap): "over" exactly.
TEST_P(ApproximateOit, SingleLayerMatchesOracle) {
  const Scene scene = planeScene(
      {{0.0, {0.9f, 0.3f, 0.2f, 0.5f}, -0.55, 0.9, 30.0}, {-0.3, {0.2f, 0.6f, 0.9f, 0.8f}, 0.55, 0.9, -20.0}},
      {0.1f, 0.2f, 0.3f});
  for (const Camera& camera : {perspectiveCamera(), orthoCamera()}) {
    SCOPED_TRACE(camera.projection == Projection::Orthographic ? "orthographic" : "perspective");
    const FragmentLists oracle = castFragments(scene, camera, 96, 72);
    ASSERT_EQ(oracle.maxCount(), 1u);
    const RenderOutput out = renderWith(scene, camera, GetParam().method, GetParam().params, 96, 72);
    expectMatches(oracle, compositeOver(oracle, scene.background), out.image, 2, 0.999);
  }
}

// The sample (20–40 layers): an approximation, but a bounded one, and it draws something.
TEST_P(ApproximateOit, SampleErrorIsBounded) {
  const Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const FragmentLists oracle = castFragments(scene, camera, 160, 120);
  const ImageRGBA8 reference = compositeOver(oracle, scene.background);
  const RenderOutput out = renderWith(scene, camera, GetParam().method, GetParam().params, 160, 120);
  const double e = rmse(reference, out.image);
  EXPECT_TRUE(std::isfinite(e));
  EXPECT_LT(e, 0.2);
  std::size_t drawn = 0;
  for (int y = 0; y < out.image.height; ++y)
    for (int x = 0; x < out.image.width; ++x) {
      const std::uint8_t* p = out.image.at(x, y);
      int d = 0;
      for (int c = 0; c < 3; ++c)
        d = std::max(d, std::abs(p[c] - static_cast<int>(std::round(scene.background[c] * 255.0f))));
      drawn += d > 8 ? 1 : 0;
    }
  EXPECT_GT(drawn, static_cast<std::size_t>(160 * 120) / 5) << "the image is (almost) only background";
  EXPECT_GT(out.stats.fragmentsGenerated, 0u);
  ::testing::Test::RecordProperty("rmse_x1e4", static_cast<int>(e * 1e4));
}

TEST_P(ApproximateOit, MemoryIsTheRenderTargets) {
  const Scene scene = makeSampleScene();
  const RenderOutput out = renderWith(scene, scene.view("front"), GetParam().method, GetParam().params, 64, 48);
  EXPECT_EQ(out.stats.bytesAllocated, 64u * 48u * GetParam().bytesPerPixel);
  EXPECT_EQ(out.stats.bytesUsed, out.stats.bytesAllocated);
  EXPECT_EQ(out.stats.fragmentsStored, 0u);  // no lists
  EXPECT_EQ(out.stats.passes, GetParam().method == "mboit" ? 2u : 1u);
}

// No fragment lists: the dump operation (exactness tests) must refuse, not return empty lists.
TEST_P(ApproximateOit, DumpOperationIsRefused) {
  context();
  const Scene scene = makeSampleScene();
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = GetParam().method;
  req.params = GetParam().params;
  req.width = 32;
  req.height = 24;
  try {
    (void)gpu.capture(scene.view("front"), req, 4);
    ADD_FAILURE() << "capture with the dump operation did not throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not supported"), std::string::npos) << e.what();
  }
}

// ---- wboit: the paper's eq. 6 ------------------------------------------------------------------

// Two overlapping planes of known colours in an orthographic view: every weight function equals
// eq. 6 evaluated by hand (w = 1 for "none"; eq. 10 on window depth; eqs. 7–9 on the distance
// behind the near plane, which is what an orthographic view-projection matrix determines).
TEST(WeightedBlendedOit, TwoLayersOrthographicMatchEquation6) {
  const glm::vec3 background(1.0f, 1.0f, 1.0f);
  const glm::vec4 front(0.9f, 0.2f, 0.1f, 0.6f), back(0.1f, 0.3f, 0.9f, 0.7f);
  // Off-centre by a fraction of a pixel: the quads' diagonals then miss the pixel centres.
  const Scene scene = planeScene({{0.5, front, 0.0137}, {-0.5, back, 0.029}}, background);
  const Camera camera = orthoCamera();
  const FragmentLists oracle = castFragments(scene, camera, 64, 48);
  ASSERT_EQ(oracle.maxCount(), 2u);
  for (const std::string weight : {"none", "eq7", "eq8", "eq9", "eq10"}) {
    SCOPED_TRACE(weight);
    const RenderOutput out = renderWith(scene, camera, "wboit", {{"weight", weight}}, 64, 48);
    const ImageRGBA8 expected =
        modelImage(oracle, [&](std::span<const Fragment> f) { return wboitPixel(f, weight, camera, background); });
    expectMatches(oracle, expected, out.image, 2, 0.999);
  }
  // By hand at the centre, w = 1: (Σ α c / Σ α)·(1 − Π(1 − α)) + Π(1 − α)·background, 8-bit inputs.
  const RenderOutput none = renderWith(scene, camera, "wboit", {{"weight", "none"}}, 64, 48);
  const glm::vec4 f = glm::unpackUnorm4x8(glm::packUnorm4x8(front)), b = glm::unpackUnorm4x8(glm::packUnorm4x8(back));
  const float reveal = (1.0f - f.a) * (1.0f - b.a);
  const glm::vec3 hand =
      (glm::vec3(f) * f.a + glm::vec3(b) * b.a) / (f.a + b.a) * (1.0f - reveal) + background * reveal;
  const std::uint8_t* p = none.image.at(32, 24);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c], hand[c] * 255.0f, 2.0) << "channel " << c;
  // …which is not "over": the front layer should dominate but does not.
  const glm::vec3 over = glm::vec3(f) * f.a + (1.0f - f.a) * (glm::vec3(b) * b.a + (1.0f - b.a) * background);
  EXPECT_GT(std::abs(hand.r - over.r) * 255.0f, 20.0f);
}

// Perspective: the depth weights use |z_eye| reconstructed from the view-projection matrix.
TEST(WeightedBlendedOit, TwoLayersPerspectiveMatchEquation6) {
  const glm::vec3 background(0.2f, 0.2f, 0.2f);
  const Scene scene = planeScene(
      {{1.5, {0.9f, 0.8f, 0.1f, 0.4f}, 0.0, 1.2, 25.0}, {-3.0, {0.1f, 0.3f, 0.9f, 0.5f}, 0.0, 4.0}}, background);
  const Camera camera = perspectiveCamera();
  const FragmentLists oracle = castFragments(scene, camera, 64, 48);
  ASSERT_EQ(oracle.maxCount(), 2u);
  for (const std::string weight : {"eq7", "eq8", "eq9", "eq10"}) {
    SCOPED_TRACE(weight);
    const RenderOutput out = renderWith(scene, camera, "wboit", {{"weight", weight}}, 64, 48);
    const ImageRGBA8 expected =
        modelImage(oracle, [&](std::span<const Fragment> f) { return wboitPixel(f, weight, camera, background); });
    expectMatches(oracle, expected, out.image, 2, 0.999);
  }
}

// Many layers: eq. 6 on the exact fragments, up to half-float accumulation (r16f revealage so
// that 8-bit rounding of the product does not dominate).
TEST(WeightedBlendedOit, SampleMatchesEquation6) {
  const Scene scene = makeSampleScene();
  const Camera camera = scene.view("front");
  const FragmentLists oracle = castFragments(scene, camera, 120, 90);
  for (const std::string weight : {"none", "eq7", "eq10"}) {
    SCOPED_TRACE(weight);
    const RenderOutput out = renderWith(scene, camera, "wboit", {{"weight", weight}, {"revealage", "r16f"}}, 120, 90);
    const ImageRGBA8 expected = modelImage(
        oracle, [&](std::span<const Fragment> f) { return wboitPixel(f, weight, camera, scene.background); });
    expectMatches(oracle, expected, out.image, 3, 0.99);
  }
}

// ---- mboit: the reconstruction for two layers --------------------------------------------------

// Two layers a_1 (front), a_2 (absorbances): the moments determine the two-point distribution, so
// the reconstruction at the front depth is exp(−β·a_1) (nothing in front, β of its own mass) and
// at the back depth exp(−a_1 − β·a_2), β the overestimation; then the paper's normalised composite.
TEST(MomentBasedOit, TwoLayersMatchTheBoundsBlend) {
  const glm::vec3 background(1.0f, 1.0f, 1.0f);
  const glm::vec4 front(0.9f, 0.2f, 0.1f, 0.6f), back(0.1f, 0.3f, 0.9f, 0.7f);
  const Scene scene = planeScene({{0.5, front}, {-0.5, back}}, background);
  const FragmentLists oracle = castFragments(scene, perspectiveCamera(), 64, 48);
  ASSERT_EQ(oracle.maxCount(), 2u);
  for (const std::string moments : {"4", "6"})
    for (const std::string beta : {"0", "0.25", "1"}) {
      SCOPED_TRACE("moments " + moments + ", overestimation " + beta);
      const RenderOutput out =
          renderWith(scene, perspectiveCamera(), "mboit", {{"moments", moments}, {"overestimation", beta}}, 64, 48);
      const double b = std::stod(beta);
      const ImageRGBA8 expected = modelImage(oracle, [&](std::span<const Fragment> frags) {
        glm::dvec3 sum(0.0);
        double sumAlpha = 0.0, absorbance = 0.0;
        for (const Fragment& f : frags) {  // sorted front to back
          const glm::dvec4 c(glm::unpackUnorm4x8(f.color));
          const double a = -std::log(1.0 - c.a);
          const double t = std::exp(-absorbance - b * a);
          sum += glm::dvec3(c) * c.a * t;
          sumAlpha += c.a * t;
          absorbance += a;
        }
        const double total = std::exp(-absorbance);
        return glm::vec3(sum / std::max(sumAlpha, 1e-5) * (1.0 - total) + glm::dvec3(background) * total);
      });
      expectMatches(oracle, expected, out.image, 2, 0.999);
    }
  // β = 0 with two layers is "over" itself.
  const RenderOutput exact = renderWith(scene, perspectiveCamera(), "mboit", {{"overestimation", "0"}}, 64, 48);
  expectMatches(oracle, compositeOver(oracle, background), exact.image, 2, 0.999);
}

}  // namespace
}  // namespace mfr::test
