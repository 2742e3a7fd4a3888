#include "dual_depth_peeling.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {
namespace {

constexpr float kEmptyRange[2] = {-2.0f, -2.0f};  // nearest 2 > farthest −2 (layers.glsl)
constexpr float kNoLayers[4] = {-1.0f, -1.0f, -1.0f, -1.0f};

}  // namespace

const MethodInfo& DualDepthPeeling::info() const {
  static const MethodInfo i{
      "peel-dual",
      "Dual depth peeling",
      "Bavoil, Myers: Order Independent Transparency with Dual Depth Peeling. NVIDIA technical report, 2008",
      true,
      {{"max_passes",
        "Max. peeling passes",
        ParamSpec::Type::Int,
        "32",
        1,
        1024,
        {},
        "peel passes at most, two layers each (plus the initialisation pass); deeper fragments are reported as "
        "overflow"}},
      "oit",
      false,
      false};
  return i;
}

void DualDepthPeeling::configure(int width, int height, const Params& params) {
  maxPasses_ = static_cast<int>(params.integer("max_passes"));
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    layers_ = gl::createTexture2D(GL_RGBA32F, width, height);
    front_ = gl::createTexture2D(GL_RGBA32F, width, height);
    back_ = gl::createTexture2D(GL_RGBA32F, width, height);
    for (int i = 0; i < 2; ++i) {
      range_[i] = gl::createTexture2D(GL_RG32F, width, height);
      peelFbo_[i] = gl::createFramebuffer();
      glNamedFramebufferTexture(peelFbo_[i].id(), GL_COLOR_ATTACHMENT0, range_[i].id(), 0);
      glNamedFramebufferTexture(peelFbo_[i].id(), GL_COLOR_ATTACHMENT1, layers_.id(), 0);
      const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
      glNamedFramebufferDrawBuffers(peelFbo_[i].id(), 2, buffers);
    }
    initFbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(initFbo_.id(), GL_COLOR_ATTACHMENT0, range_[0].id(), 0);
    glNamedFramebufferTexture(initFbo_.id(), GL_COLOR_ATTACHMENT1, front_.id(), 0);
    accumFbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(accumFbo_.id(), GL_COLOR_ATTACHMENT0, front_.id(), 0);
    glNamedFramebufferTexture(accumFbo_.id(), GL_COLOR_ATTACHMENT1, back_.id(), 0);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(accumFbo_.id(), 2, buffers);
    noAttachFbo_ = gl::createFramebuffer();
    glNamedFramebufferParameteri(noAttachFbo_.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, width);
    glNamedFramebufferParameteri(noAttachFbo_.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, height);
  }
  if (!emptyVao_) emptyVao_ = gl::createVertexArray();
  if (!peel_.id()) {
    peel_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/peel-dual/peel.geom.frag"}});
    blend_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "methods/peel-dual/blend.screen.frag"}});
    remaining_ = gl::Program({{GL_VERTEX_SHADER, "common/fullscreen.vert"},
                              {GL_FRAGMENT_SHADER, "methods/peel-dual/remaining.screen.frag"}});
    final_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "methods/peel-dual/final.screen.frag"}});
  }
}

void DualDepthPeeling::capture(const FrameContext&) {
  stats_ = Stats{};
}

void DualDepthPeeling::resolve(const FrameContext& ctx, const Operation& op) {
  const bool dump = op.name == "dump";
  if (!dump && op.name != "oit")
    throw Error("--op " + op.name, "peel-dual composites while it peels: it supports only the operation oit");
  const gl::Program* dumpProgram = nullptr;
  if (dump) {
    dumpProgram = &dumpPrograms_.get("peel-dual", op, {}, "dump.screen.frag");
    if (op.bind) op.bind(*dumpProgram);
    dumpProgram->set("uMaxLayers", static_cast<unsigned>(2 * maxPasses_));
  }
  stats_ = Stats{};
  GLint target = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);
  glViewport(0, 0, width_, height_);
  const auto fullScreen = [&](const gl::Program& program) {
    program.use();
    glBindVertexArray(emptyVao_.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
  };
  const auto sideEffectsOnly = [] {
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  };

  // Initialisation pass: the first range (MAX of (−z, z)); in dump frames also the per-pixel
  // fragment count (ADD into front_, which a dump frame does not composite into). Its query counts
  // every fragment rasterised.
  glClearTexImage(range_[0].id(), 0, GL_RG, GL_FLOAT, kEmptyRange);
  const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  if (dump) glClearTexImage(front_.id(), 0, GL_RGBA, GL_FLOAT, zero);
  const GLenum initBuffers[2] = {GL_COLOR_ATTACHMENT0,
                                 dump ? static_cast<GLenum>(GL_COLOR_ATTACHMENT1) : static_cast<GLenum>(GL_NONE)};
  glNamedFramebufferDrawBuffers(initFbo_.id(), 2, initBuffers);
  glBindFramebuffer(GL_FRAMEBUFFER, initFbo_.id());
  peel_.set("uInit", 1);
  {
    GeometryPassState state(true, false);
    glEnable(GL_BLEND);
    glBlendEquationi(0, GL_MAX);
    glBlendEquationi(1, GL_FUNC_ADD);
    glBlendFunci(1, GL_ONE, GL_ONE);
    ctx.timer.begin("init");
    stats_.fragmentsGenerated = countSamples([&] { ctx.scene.draw(peel_, ctx.frame); });
    ctx.timer.end();
  }
  peel_.set("uInit", 0);
  stats_.passes = 1;

  if (dump) {
    sideEffectsOnly();
    glBindFramebuffer(GL_FRAMEBUFFER, noAttachFbo_.id());
    glBindTextureUnit(MFR_TEX_AUX2, front_.id());
    dumpProgram->set("uWriteCounts", 1);
    fullScreen(*dumpProgram);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    dumpProgram->set("uWriteCounts", 0);
  } else {
    const float frontInit[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // C = 0, T = 1
    const float backInit[4] = {ctx.background.r, ctx.background.g, ctx.background.b, 1.0f};
    glClearTexImage(front_.id(), 0, GL_RGBA, GL_FLOAT, frontInit);
    glClearTexImage(back_.id(), 0, GL_RGBA, GL_FLOAT, backInit);
  }

  // Layer counts: queries on the counting pass, read once after the last pass so that they add
  // no wait. The first range's non-empty pixels, and per pass the pixels that peel two layers.
  std::vector<gl::Query> layerQueries;
  const auto queueLayerCount = [&](const gl::Texture& range, int twoLayers) {
    sideEffectsOnly();
    glBindFramebuffer(GL_FRAMEBUFFER, noAttachFbo_.id());
    glBindTextureUnit(MFR_TEX_AUX0, range.id());
    remaining_.set("uTwoLayers", twoLayers);
    layerQueries.push_back(gl::createQuery(GL_SAMPLES_PASSED));
    ctx.timer.begin("layer count");
    glBeginQuery(GL_SAMPLES_PASSED, layerQueries.back().id());
    fullScreen(remaining_);
    glEndQuery(GL_SAMPLES_PASSED);
    ctx.timer.end();
    remaining_.set("uTwoLayers", 0);
  };

  int cur = 0;
  std::uint64_t remainingPixels = stats_.fragmentsGenerated > 0 ? 1 : 0;
  std::uint64_t layersComposited = 0;  // one per non-empty range a pass peels, two where its ends differ
  std::uint32_t peelPasses = 0;
  if (remainingPixels > 0) queueLayerCount(range_[0], 0);
  while (remainingPixels > 0 && peelPasses < static_cast<std::uint32_t>(maxPasses_)) {
    const int next = 1 - cur;
    queueLayerCount(range_[cur], 1);
    // Peel the front and back layers of range_[cur]; the fragments between form range_[next].
    glClearTexImage(range_[next].id(), 0, GL_RG, GL_FLOAT, kEmptyRange);
    glClearTexImage(layers_.id(), 0, GL_RGBA, GL_FLOAT, kNoLayers);
    glBindFramebuffer(GL_FRAMEBUFFER, peelFbo_[next].id());
    glBindTextureUnit(MFR_TEX_AUX0, range_[cur].id());
    {
      GeometryPassState state(true, false);
      glEnable(GL_BLEND);
      glBlendEquation(GL_MAX);
      ctx.timer.begin("peel");
      ctx.scene.draw(peel_, ctx.frame);
      ctx.timer.end();
    }
    ++stats_.passes;

    glBindTextureUnit(MFR_TEX_AUX0, range_[cur].id());
    glBindTextureUnit(MFR_TEX_AUX1, layers_.id());
    if (dump) {
      sideEffectsOnly();
      glBindFramebuffer(GL_FRAMEBUFFER, noAttachFbo_.id());
      glBindTextureUnit(MFR_TEX_AUX2, front_.id());
      dumpProgram->set("uPass", peelPasses);
      ctx.timer.begin("dump");
      fullScreen(*dumpProgram);
      ctx.timer.end();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    } else {
      glBindFramebuffer(GL_FRAMEBUFFER, accumFbo_.id());
      glDisable(GL_DEPTH_TEST);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      glEnable(GL_BLEND);
      glBlendEquation(GL_FUNC_ADD);
      glBlendFuncSeparatei(0, GL_DST_ALPHA, GL_ONE, GL_ZERO, GL_ONE_MINUS_SRC_ALPHA);  // under
      glBlendFuncSeparatei(1, GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);        // over
      ctx.timer.begin("blend");
      fullScreen(blend_);
      ctx.timer.end();
    }
    ++peelPasses;

    // Stop when no pixel has fragments left between its front and back layers.
    sideEffectsOnly();
    glBindFramebuffer(GL_FRAMEBUFFER, noAttachFbo_.id());
    glBindTextureUnit(MFR_TEX_AUX0, range_[next].id());
    ctx.timer.begin("stop query");
    remainingPixels = countSamples([&] { fullScreen(remaining_); });
    ctx.timer.end();
    cur = next;
    // The next pass peels one layer at each of these pixels (its front).
    if (peelPasses < static_cast<std::uint32_t>(maxPasses_)) layersComposited += remainingPixels;
  }
  for (const gl::Query& query : layerQueries) {
    GLuint64 pixels = 0;
    glGetQueryObjectui64v(query.id(), GL_QUERY_RESULT, &pixels);
    layersComposited += pixels;
  }

  if (remainingPixels > 0) {
    // The pass limit was reached: one more peel pass, counting only, measures the fragments left
    // in the unpeeled ranges (the dropped ones).
    stats_.overflowPixels = remainingPixels;
    sideEffectsOnly();
    glBindFramebuffer(GL_FRAMEBUFFER, noAttachFbo_.id());
    glBindTextureUnit(MFR_TEX_AUX0, range_[cur].id());
    {
      GeometryPassState state(false, false);
      ctx.timer.begin("overflow check");
      stats_.fragmentsDropped = countSamples([&] { ctx.scene.draw(peel_, ctx.frame); });
      ctx.timer.end();
    }
    ++stats_.passes;
  }

  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ZERO);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  if (!dump) {
    glBindTextureUnit(MFR_TEX_AUX1, front_.id());
    glBindTextureUnit(MFR_TEX_AUX2, back_.id());
    ctx.timer.begin("final");
    fullScreen(final_);
    ctx.timer.end();
  }
  glBindVertexArray(0);

  stats_.overflow = stats_.fragmentsDropped > 0;
  stats_.fragmentsStored = std::min(layersComposited, stats_.fragmentsGenerated - stats_.fragmentsDropped);
  // What is neither composited nor left in an unpeeled range lay at a peeled layer's depth.
  const std::uint64_t ties = stats_.fragmentsGenerated - stats_.fragmentsDropped - stats_.fragmentsStored;
  stats_.bytesAllocated = kBytesPerPixel * static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_);
  stats_.bytesUsed = stats_.bytesAllocated;
  stats_.kMin = stats_.kMax = static_cast<std::uint32_t>(2 * maxPasses_);
  stats_.notes.emplace_back("peel passes", std::to_string(peelPasses));
  stats_.notes.emplace_back("max_passes", std::to_string(maxPasses_));
  if (ties > 0) stats_.notes.emplace_back("depth ties", depthTiesNote(ties));
  stats_.notes.emplace_back("capture/resolve", "all passes run in resolve: peeling composites while it peels");
}

Stats DualDepthPeeling::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "none";  // passes are ordered by GL; an occlusion query per pass decides when to stop
  return s;
}

}  // namespace mfr
