// The k-buffer family against the oracle: classic k-buffer (Bavoil et al. 2007), k+-buffer
// max-array (plain and revised) and max-heap (Vasilakis et al. 2015), and k-peeling. For each k:
// the captured set is the oracle's k nearest fragments per pixel, k = 1 is a z-buffer, k >= max
// n(p) is the A-buffer; k-peeling is exact for every k; no spin-lock failures; memory accounting
// equals the allocation formula; the tail hook holds exactly the fragments beyond the k nearest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>

#include "../../mfrcore/src/methods/kbuffer_common.hpp"
#include "../../mfrcore/src/methods/prefix_sum.hpp"
#include "exact_method.hpp"
#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

constexpr int kW = 96, kH = 72;

struct Variant {
  std::string method;
  std::map<std::string, std::string> params;
  std::string label;
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.label;
}

const std::vector<Variant>& variants() {
  static const std::vector<Variant> v{
      {"kbuffer", {}, "kbuffer"},
      {"kplus-array", {}, "kplus_array"},
      {"kplus-array", {{"revised", "true"}}, "kplus_array_revised"},
      {"kplus-array", {{"culling", "false"}}, "kplus_array_noculling"},
      {"kplus-heap", {}, "kplus_heap"},
      {"kplus-heap", {{"culling", "false"}}, "kplus_heap_noculling"},
      {"kplus-sbuffer", {}, "kplus_sbuffer_array"},
      {"kplus-sbuffer", {{"structure", "heap"}}, "kplus_sbuffer_heap"},
  };
  return v;
}

// The sample scene, its front camera and its oracle at kW x kH, computed once.
const SampleReference& reference() {
  return sampleReference("front", kW, kH);
}

RenderRequest request(const std::string& method, std::map<std::string, std::string> params, int k) {
  RenderRequest req;
  req.method = method;
  req.params = std::move(params);
  req.params["k"] = std::to_string(k);
  req.width = kW;
  req.height = kH;
  return req;
}

std::uint64_t pixels() {
  return static_cast<std::uint64_t>(kW) * kH;
}

class KBufferVariant : public ::testing::TestWithParam<Variant> {};

// Per pixel, the captured set equals the oracle's k nearest fragments (non-ambiguous pixels), and
// no fragment was lost to the spin lock.
TEST_P(KBufferVariant, CapturesTheKNearest) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  for (int k : {1, 2, 4, 8, 16, 32}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    const RenderRequest req = request(GetParam().method, GetParam().params, k);
    const CapturedLists lists = gpu.capture(ref.camera, req, k);
    const ListComparison lc = compareLists(ref.oracle, lists, static_cast<std::uint32_t>(k));
    EXPECT_GT(lc.compared, lc.pixels * 7 / 10);
    EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
    EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
    EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;
    const RenderOutput out = gpu.render(ref.camera, req);
    EXPECT_EQ(out.stats.lockFailures, 0u);
    EXPECT_EQ(out.stats.sync, "spinlock");
    EXPECT_EQ(out.stats.fragmentsGenerated, out.stats.fragmentsStored + out.stats.fragmentsDropped);
    EXPECT_LE(out.stats.fragmentsStored, pixels() * static_cast<std::uint64_t>(k));
  }
}

// The same on real CAD files (occt-misc bearing STL, the assimp 2CylinderEngine assembly), made
// transparent so every layer is a candidate.
TEST_P(KBufferVariant, CapturesTheKNearestOnRealModels) {
  context();
  for (const char* path : {"/usr/share/opencascade/data/stl/bearing.stl",
                           "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}) {
    SCOPED_TRACE(path);
    Scene scene = loadScene(path);
    for (Object& o : scene.objects) o.material.color.a = 0.4f;
    const Camera camera = scene.view("iso");
    const FragmentLists oracle = castFragments(scene, camera, kW, kH);
    GpuRenderer gpu;
    gpu.setScene(scene);
    for (int k : {1, 2, 4, 8, 16, 32}) {
      SCOPED_TRACE("k=" + std::to_string(k));
      const RenderRequest req = request(GetParam().method, GetParam().params, k);
      const CapturedLists lists = gpu.capture(camera, req, k);
      const ListComparison lc = compareLists(oracle, lists, static_cast<std::uint32_t>(k));
      EXPECT_GT(lc.compared, lc.pixels * 7 / 10);
      EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
      EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
      EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;
    }
  }
}

// k = 1 is a z-buffer: the nearest fragment's colour over the background.
TEST_P(KBufferVariant, KOneIsAZBuffer) {
  context();
  const SampleReference& ref = reference();
  ImageRGBA8 zbuffer(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const auto all = ref.oracle.pixel(x, y);
      const glm::vec3 c = compositeOver(all.first(std::min<std::size_t>(all.size(), 1)), ref.scene.background);
      for (int ch = 0; ch < 3; ++ch)
        zbuffer.at(x, y)[ch] = static_cast<std::uint8_t>(std::lround(std::clamp(c[ch], 0.0f, 1.0f) * 255.0f));
      zbuffer.at(x, y)[3] = 255;
    }
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  const RenderOutput out = gpu.render(ref.camera, request(GetParam().method, GetParam().params, 1));
  const ImageComparison ic = compareImages(ref.oracle, zbuffer, out.image, 2);
  EXPECT_GE(ic.fraction(), 0.999) << (ic.compared - ic.within) << " pixels off; max " << ic.maxDifference;
}

// k >= max n(p): the A-buffer image, nothing dropped.
TEST_P(KBufferVariant, LargeKIsTheABuffer) {
  context();
  const SampleReference& ref = reference();
  const int k = static_cast<int>(ref.oracle.maxCount()) + 2;  // margin for edge pixels
  ASSERT_LE(k, 256);
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  const RenderOutput out = gpu.render(ref.camera, request(GetParam().method, GetParam().params, k));
  const ImageComparison ic = compareImages(ref.oracle, ref.image, out.image, 2);
  EXPECT_GE(ic.fraction(), 0.999) << (ic.compared - ic.within) << " pixels off; max " << ic.maxDifference;
  EXPECT_FALSE(out.stats.overflow);
  EXPECT_EQ(out.stats.fragmentsDropped, 0u);
  EXPECT_EQ(out.stats.lockFailures, 0u);
}

// Memory accounting equals the allocation: k slots of 8 bytes per pixel (kplus-sbuffer: Σ min(n, k)
// slots, plus two (W·H+1)-uint buffers for the bounded counts and offsets and the prefix sum's
// scratch), a 4-byte semaphore per pixel (spin lock), 8 bytes of per-pixel counters (revised
// max-array), 20 bytes of tail sums per pixel (tail on), 32 bytes of statistics counters.
TEST_P(KBufferVariant, MemoryAccountingMatchesFormula) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  for (bool tail : {false, true}) {
    auto params = GetParam().params;
    params["tail"] = tail ? "true" : "false";
    const int k = 6;
    RenderRequest req = request(GetParam().method, params, k);
    if (tail) req.operation = "hybrid";  // the one operation that reads the tail (refused elsewhere)
    const RenderOutput out = gpu.render(ref.camera, req);
    const bool revised = params.count("revised") && params.at("revised") == "true";
    const std::uint64_t perPixel = 4u + (revised ? 8u : 0u) + (tail ? 20u : 0u);
    if (GetParam().method == "kplus-sbuffer") {
      // Every one of the Σ min(n(p), k) slots is filled.
      std::uint64_t slots = 0;
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) slots += std::min<std::uint32_t>(ref.oracle.count(x, y), k);
      EXPECT_NEAR(static_cast<double>(out.stats.fragmentsStored), static_cast<double>(slots), 0.01 * slots);
      const std::uint64_t scan = 4 * PrefixSum::scratchElements(pixels() + 1);
      EXPECT_EQ(out.stats.bytesAllocated,
                out.stats.fragmentsStored * 8u + pixels() * perPixel + 2 * (pixels() + 1) * 4 + scan + 32u);
      EXPECT_EQ(out.stats.bytesUsed, out.stats.bytesAllocated);
    } else {
      EXPECT_EQ(out.stats.bytesAllocated, pixels() * (8u * k + perPixel) + 32u) << "tail=" << tail;
      EXPECT_EQ(out.stats.bytesUsed, out.stats.bytesAllocated - (pixels() * k - out.stats.fragmentsStored) * 8u);
    }
    EXPECT_EQ(out.stats.kMax, static_cast<std::uint32_t>(k));
  }
}

// The tail hook: per pixel, the sums over the fragments beyond the k nearest (colours compared
// with the 2/255 tolerance of the list comparison, per fragment).
TEST_P(KBufferVariant, TailHoldsTheFragmentsBeyondK) {
  context();
  const SampleReference& ref = reference();
  gl::GpuScene scene(ref.scene);
  std::unique_ptr<Method> method = createMethod(GetParam().method);
  auto params = GetParam().params;
  params["tail"] = "true";
  const int k = 3;
  params["k"] = std::to_string(k);
  method->configure(kW, kH, Params(method->info().params, params, GetParam().method));
  auto* family = dynamic_cast<KBufferFamily*>(method.get());
  ASSERT_NE(family, nullptr);
  ASSERT_TRUE(family->tailEnabled());

  gl::Texture color = gl::createTexture2D(GL_RGBA8, kW, kH);
  gl::Framebuffer fbo = gl::createFramebuffer();
  glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0, color.id(), 0);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, kW, kH);
  gl::PassTimer timer;
  gl::FrameUniforms frame;
  frame.viewProj = glm::mat4(ref.camera.projectionMatrix(static_cast<double>(kW) / kH) * ref.camera.viewMatrix());
  frame.viewDir = glm::vec3(ref.camera.forward());
  const FrameContext ctx{scene, frame, ref.scene.background, kW, kH, timer};
  method->capture(ctx);
  method->resolve(ctx, oitOperation());
  timer.collect();
  gl::checkErrors("tail test");
  const std::vector<KBufferTail> tail = family->readTail();
  ASSERT_EQ(tail.size(), pixels());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);

  std::size_t compared = 0, bad = 0, nonEmpty = 0;
  std::string first;
  std::uint64_t tailTotal = 0;
  for (const KBufferTail& t : tail) tailTotal += t.count;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (ref.oracle.isAmbiguous(x, y)) continue;
      ++compared;
      const auto all = ref.oracle.pixel(x, y);
      std::int64_t expect[4] = {0, 0, 0, 0};
      std::uint32_t n = 0;
      for (std::size_t i = static_cast<std::size_t>(k); i < all.size(); ++i, ++n) {
        const std::uint32_t c = all[i].color;
        const std::int64_t a = (c >> 24) & 0xFF;
        for (int ch = 0; ch < 3; ++ch) expect[ch] += static_cast<std::int64_t>((c >> (8 * ch)) & 0xFF) * a;
        expect[3] += a;
      }
      const KBufferTail& t = tail[static_cast<std::size_t>(y) * kW + x];
      // Per fragment, colour and alpha may differ by 2/255: |Δ(c·α)| <= 2·255 + 2·255 + 4.
      bool ok = t.count == n && std::llabs(static_cast<std::int64_t>(t.alpha) - expect[3]) <= 2 * n;
      for (int ch = 0; ch < 3; ++ch)
        ok = ok && std::llabs(static_cast<std::int64_t>(t.colorAlpha[ch]) - expect[ch]) <=
                       1024 * static_cast<std::int64_t>(n);
      nonEmpty += n > 0;
      if (!ok && ++bad == 1)
        first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): count " + std::to_string(t.count) +
                " oracle " + std::to_string(n) + ", Σα " + std::to_string(t.alpha) + " oracle " +
                std::to_string(expect[3]);
    }
  EXPECT_GT(nonEmpty, compared / 10) << "the scene should have deep pixels";
  EXPECT_EQ(bad, 0u) << first;
  const Stats s = method->stats();
  EXPECT_EQ(tailTotal, s.fragmentsDropped) << "every fragment not kept is in the tail once";
}

INSTANTIATE_TEST_SUITE_P(KBuffer, KBufferVariant, ::testing::ValuesIn(variants()),
                         [](const ::testing::TestParamInfo<Variant>& p) { return p.param.label; });

// Large k through the shared exact-method tests (counts, depths, colours, images, real models).
INSTANTIATE_TEST_SUITE_P(
    KBufferLargeK, ExactMethod,
    ::testing::Values(ExactCase{"kplus-array", {{"k", "256"}, {"revised", "true"}}, "k256_revised"},
                      ExactCase{"kplus-heap", {{"k", "256"}}, "k256"}, ExactCase{"kpeel", {{"k", "4"}}, "k4"},
                      ExactCase{"kplus-sbuffer", {{"k", "256"}}, "k256"},
                      ExactCase{"kplus-dynamic", {{"robustness", "1"}, {"budget_mib", "256"}}, "full"}),
    exactCaseName);

// Interlock: used where the driver has it, and then capturing the oracle's k nearest like the
// spin lock; refused with a clear message where it does not (llvmpipe).
TEST(KBuffer, InterlockIsUsedOrRefused) {
  const bool has = context().info().fragmentShaderInterlock;
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  for (const char* method : {"kbuffer", "kplus-array", "kplus-heap", "kpeel", "kplus-sbuffer", "kplus-dynamic"}) {
    SCOPED_TRACE(method);
    RenderRequest req = request(method, {{"sync", "interlock"}}, 4);
    if (std::string(method) == "kplus-dynamic") req.params.erase("k");  // chosen per frame
    if (has) {
      const RenderOutput out = gpu.render(ref.camera, req);
      EXPECT_EQ(out.stats.sync, "interlock");
      EXPECT_EQ(out.stats.lockFailures, 0u);
      EXPECT_EQ(out.stats.fragmentsGenerated, out.stats.fragmentsStored + out.stats.fragmentsDropped);
      if (std::string(method) == "kplus-dynamic") continue;
      // The critical section must give what the spin lock gives: the k nearest, or with k-peeling
      // (exact for every k) every fragment.
      const bool exact = std::string(method) == "kpeel";
      for (int k : {1, 4, 16}) {
        SCOPED_TRACE("k=" + std::to_string(k));
        const RenderRequest kreq = request(method, {{"sync", "interlock"}}, k);
        const ListComparison lc = compareLists(ref.oracle, gpu.capture(ref.camera, kreq, exact ? 64 : k),
                                               exact ? 0u : static_cast<std::uint32_t>(k));
        EXPECT_GT(lc.compared, lc.pixels * 7 / 10);
        EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
        EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
        EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;
      }
    } else {
      try {
        gpu.render(ref.camera, req);
        ADD_FAILURE() << "interlock accepted without the extension";
      } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "--param sync=interlock: not supported by this OpenGL driver");
      }
    }
  }
}

TEST(KBuffer, BadParametersAreRefused) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  EXPECT_THROW(gpu.render(ref.camera, request("kplus-array", {}, 0)), Error);
  EXPECT_THROW(gpu.render(ref.camera, request("kplus-array", {}, 257)), Error);
  EXPECT_THROW(gpu.render(ref.camera, request("kplus-heap", {{"sync", "mutex"}}, 4)), Error);
  EXPECT_THROW(gpu.render(ref.camera, request("kbuffer", {{"revised", "true"}}, 4)), Error);
}

// k-peeling equals the A-buffer image for every k, captures every fragment exactly once and never
// fails a lock.
TEST(KPeeling, EqualsTheABufferForEveryK) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  RenderRequest abuffer;
  abuffer.method = "abuffer-ll";
  abuffer.width = kW;
  abuffer.height = kH;
  const ImageRGBA8 abufferImage = gpu.render(ref.camera, abuffer).image;
  for (int k : {1, 2, 4, 8, 16, 32}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    const RenderOutput out = gpu.render(ref.camera, request("kpeel", {}, k));
    // Bit for bit the A-buffer's image, which composites the same sorted fragments in one pass:
    // the transmittance carried between iterations as 1 - T put 1 to 3 pixels 1/255 off (a review).
    std::size_t differ = 0;
    for (std::size_t i = 0; i < out.image.pixels.size(); ++i) differ += out.image.pixels[i] != abufferImage.pixels[i];
    EXPECT_EQ(differ, 0u) << "channels differing from abuffer-ll";
    const ImageComparison ic = compareImages(ref.oracle, ref.image, out.image, 2);
    EXPECT_GE(ic.fraction(), 0.999) << (ic.compared - ic.within) << " pixels off; max " << ic.maxDifference;
    EXPECT_EQ(out.stats.fragmentsStored, out.stats.fragmentsGenerated);
    EXPECT_EQ(out.stats.lockFailures, 0u);
    EXPECT_FALSE(out.stats.overflow);
    const std::uint32_t iterations =
        (ref.oracle.maxCount() + static_cast<std::uint32_t>(k) - 1) / static_cast<std::uint32_t>(k);
    EXPECT_NEAR(out.stats.passes, 1.0 + iterations, 1.0);  // rasterised max n(p) may differ by one at edges
    EXPECT_EQ(out.stats.bytesAllocated, pixels() * (16u * k + 32u + 4u) + 32u);
  }
}

// The iteration bound: fewer passes than ceil(max n(p) / k) drop the farthest fragments, reported
// as overflow; an operation that is neither oit nor stateless is refused.
TEST(KPeeling, IterationBoundAndOperationsAreEnforced) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  const RenderOutput out = gpu.render(ref.camera, request("kpeel", {{"max_iterations", "2"}}, 1));
  EXPECT_EQ(out.stats.passes, 3u);
  EXPECT_TRUE(out.stats.overflow);
  EXPECT_GT(out.stats.fragmentsDropped, 0u);
  EXPECT_LE(out.stats.fragmentsStored, 2u * pixels());
  // The pixels that lost fragments: those with more than 2 (iterations × k), as the oracle counts
  // them but for pixels on an edge, where the two may see a fragment more or less (it said 0).
  std::uint64_t deeper = 0, edges = 0;  // deeper: away from edges
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool edge = ref.oracle.flags[ref.oracle.index(x, y)] != 0;
      deeper += !edge && ref.oracle.count(x, y) > 2;
      edges += edge;
    }
  EXPECT_GT(deeper, pixels() / 10);
  EXPECT_GE(out.stats.overflowPixels, deeper);
  EXPECT_LE(out.stats.overflowPixels, deeper + edges);

  std::unique_ptr<Method> method = createMethod("kpeel");
  method->configure(kW, kH, Params(method->info().params, {{"k", "2"}}, "kpeel"));
  gl::GpuScene scene(ref.scene);
  gl::PassTimer timer;
  const FrameContext ctx{scene, gl::FrameUniforms{}, ref.scene.background, kW, kH, timer};
  method->capture(ctx);
  EXPECT_THROW(method->resolve(ctx, Operation{"csg", "ops/oit.glsl", nullptr}), Error);
  timer.collect();
}

// Per-pixel lists through the dump operation (stateless, so it streams across the iterations).
TEST(KPeeling, DumpListsEqualTheOracleForSmallK) {
  context();
  const SampleReference& ref = reference();
  GpuRenderer gpu;
  gpu.setScene(ref.scene);
  for (int k : {1, 3}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    const CapturedLists lists =
        gpu.capture(ref.camera, request("kpeel", {}, k), static_cast<int>(ref.oracle.maxCount()));
    const ListComparison lc = compareLists(ref.oracle, lists);
    EXPECT_EQ(lc.countMismatches, 0u) << lc.firstMismatch;
    EXPECT_EQ(lc.depthMismatches, 0u) << lc.firstMismatch;
    EXPECT_EQ(lc.colorMismatches, 0u) << lc.firstMismatch;
  }
}

// Equal depths: coplanar quads of different colours (a tie group of 4 at every covered pixel,
// behind one front quad). Peeling by the (depth, object, primitive) key composites each fragment
// exactly once whatever k cuts through the group, in the same order: the images are identical.
TEST(KPeeling, TiesAtEqualDepthAreCompositedOnce) {
  context();
  Scene scene;
  scene.name = "ties";
  const auto quad = std::make_shared<const Mesh>(makePlane(2.0, 2.0));
  const glm::vec4 colors[5] = {{0.9f, 0.2f, 0.2f, 0.5f},
                               {0.2f, 0.9f, 0.2f, 0.5f},
                               {0.2f, 0.2f, 0.9f, 0.5f},
                               {0.9f, 0.9f, 0.2f, 0.5f},
                               {0.5f, 0.5f, 0.5f, 0.3f}};
  for (int i = 0; i < 5; ++i) {
    Object o;
    o.name = "quad" + std::to_string(i);
    o.mesh = quad;
    o.material.color = colors[i];
    if (i == 4) o.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.3, 0.2, 0.5));
    scene.objects.push_back(o);
  }
  Camera cam;
  cam.eye = {0.0, 0.0, 4.0};
  cam.nearPlane = 1.0;
  cam.farPlane = 10.0;
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req = request("kpeel", {}, 64);
  const RenderOutput all = gpu.render(cam, req);
  EXPECT_EQ(all.stats.fragmentsStored, all.stats.fragmentsGenerated);
  for (int k : {1, 2, 3, 4}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    req.params["k"] = std::to_string(k);
    const RenderOutput out = gpu.render(cam, req);
    EXPECT_EQ(out.stats.fragmentsStored, out.stats.fragmentsGenerated);
    EXPECT_EQ(out.stats.lockFailures, 0u);
    EXPECT_EQ(out.image.pixels, all.image.pixels);
  }
}

}  // namespace
}  // namespace mfr::test
