#include "depth_peeling_front_to_back.hpp"

#include <algorithm>
#include <bit>
#include <string>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {

const MethodInfo& DepthPeelingFrontToBack::info() const {
  static const MethodInfo i{
      "peel-f2b",
      "Front-to-back depth peeling",
      "Everitt: Interactive Order-Independent Transparency. NVIDIA technical report, 2001",
      true,
      {{"max_passes",
        "Max. peeling passes",
        ParamSpec::Type::Int,
        "64",
        1,
        1024,
        {},
        "layers peeled at most (one geometry pass each); deeper fragments are reported as overflow"}},
      "oit",
      false,
      false};
  return i;
}

void DepthPeelingFrontToBack::configure(int width, int height, const Params& params) {
  maxPasses_ = static_cast<int>(params.integer("max_passes"));
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    depth_ = gl::createTexture2D(GL_DEPTH_COMPONENT32F, width, height);
    accum_ = gl::createTexture2D(GL_RGBA32F, width, height);
    accumFbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(accumFbo_.id(), GL_COLOR_ATTACHMENT0, accum_.id(), 0);
    for (int i = 0; i < 2; ++i) {
      layers_[i] = gl::createTexture2D(GL_RG32UI, width, height);
      peelFbo_[i] = gl::createFramebuffer();
      glNamedFramebufferTexture(peelFbo_[i].id(), GL_COLOR_ATTACHMENT0, layers_[i].id(), 0);
      glNamedFramebufferTexture(peelFbo_[i].id(), GL_DEPTH_ATTACHMENT, depth_.id(), 0);
    }
  }
  if (!emptyVao_) emptyVao_ = gl::createVertexArray();
  if (!peel_.id()) {
    peel_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/peel-f2b/peel.geom.frag"}});
    blend_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "methods/peel-f2b/blend.screen.frag"}});
    final_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "methods/peel-f2b/final.screen.frag"}});
  }
}

void DepthPeelingFrontToBack::capture(const FrameContext&) {
  stats_ = Stats{};
}

void DepthPeelingFrontToBack::resolve(const FrameContext& ctx, const Operation& op) {
  const bool dump = op.name == "dump";
  if (!dump && op.name != "oit")
    throw Error("--op " + op.name, "peel-f2b composites while it peels: it supports only the operation oit");
  const gl::Program* dumpProgram = nullptr;
  if (dump) {
    dumpProgram = &dumpPrograms_.get("peel-f2b", op, {}, "dump.screen.frag");
    if (op.bind) op.bind(*dumpProgram);
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

  // "Previous layer" of the first pass: depth -1, so every fragment lies behind it.
  const GLuint beforeFirst[2] = {0u, std::bit_cast<GLuint>(-1.0f)};
  const GLuint empty[2] = {0u, MFR_NIL};
  const float accumInit[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // C = 0, T = 1
  const float farDepth = 1.0f;
  glClearTexImage(layers_[1].id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, beforeFirst);
  glClearTexImage(accum_.id(), 0, GL_RGBA, GL_FLOAT, accumInit);

  glBindFramebuffer(GL_FRAMEBUFFER, accumFbo_.id());
  if (dump) {
    // Every pixel starts with count 0; peeled layers raise it.
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    dumpProgram->set("uWriteCounts", 1);
    fullScreen(*dumpProgram);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    dumpProgram->set("uWriteCounts", 0);
  }

  // Count pass: every fragment lies behind the "before first" layer, so with the depth test and
  // colour writes off the query counts all rasterised fragments. Peeling alone cannot know them:
  // a fragment at exactly a peeled layer's depth is never peeled (a coplanar tie).
  glBindFramebuffer(GL_FRAMEBUFFER, peelFbo_[0].id());
  glBindTextureUnit(MFR_TEX_AUX0, layers_[1].id());
  {
    GeometryPassState state(false, false);
    ctx.timer.begin("count");
    stats_.fragmentsGenerated = countSamples([&] { ctx.scene.draw(peel_, ctx.frame); });
    ctx.timer.end();
  }
  ++stats_.passes;

  int cur = 0;
  bool exhausted = false;
  std::uint32_t layersPeeled = 0;
  for (int layer = 0; layer < maxPasses_; ++layer) {
    // Peel: nearest fragment strictly behind the previous layer.
    glClearTexImage(layers_[cur].id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, empty);
    glClearTexImage(depth_.id(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, &farDepth);
    glBindFramebuffer(GL_FRAMEBUFFER, peelFbo_[cur].id());
    glBindTextureUnit(MFR_TEX_AUX0, layers_[1 - cur].id());
    {
      GeometryPassState state(true, true);
      glDepthFunc(GL_LESS);
      glDepthMask(GL_TRUE);
      ctx.timer.begin("peel");
      ctx.scene.draw(peel_, ctx.frame);
      ctx.timer.end();
    }
    ++stats_.passes;

    // Composite it (or hand it to the dump operation); the query counts its fragments.
    glBindFramebuffer(GL_FRAMEBUFFER, accumFbo_.id());
    glBindTextureUnit(MFR_TEX_AUX1, layers_[cur].id());
    glDisable(GL_DEPTH_TEST);
    std::uint64_t pixels = 0;
    if (dump) {
      glDisable(GL_BLEND);
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);  // SSBO writes only
      dumpProgram->set("uLayerIndex", static_cast<unsigned>(layer));
      ctx.timer.begin("dump");
      pixels = countSamples([&] { fullScreen(*dumpProgram); });
      ctx.timer.end();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    } else {
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      glEnable(GL_BLEND);
      glBlendEquation(GL_FUNC_ADD);
      glBlendFuncSeparate(GL_DST_ALPHA, GL_ONE, GL_ZERO, GL_ONE_MINUS_SRC_ALPHA);
      ctx.timer.begin("blend");
      pixels = countSamples([&] { fullScreen(blend_); });
      ctx.timer.end();
      glDisable(GL_BLEND);
    }
    if (pixels == 0) {
      exhausted = true;
      break;
    }
    stats_.fragmentsStored += pixels;
    ++layersPeeled;
    cur = 1 - cur;
  }

  if (!exhausted) {
    // The pass limit was reached: one more peel pass with the depth test off counts every
    // fragment behind the last layer (the dropped ones) and marks their pixels.
    glClearTexImage(layers_[cur].id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, empty);
    glBindFramebuffer(GL_FRAMEBUFFER, peelFbo_[cur].id());
    glBindTextureUnit(MFR_TEX_AUX0, layers_[1 - cur].id());
    {
      GeometryPassState state(true, false);
      ctx.timer.begin("overflow check");
      stats_.fragmentsDropped = countSamples([&] { ctx.scene.draw(peel_, ctx.frame); });
      ctx.timer.end();
    }
    ++stats_.passes;
    if (stats_.fragmentsDropped > 0) {
      glBindFramebuffer(GL_FRAMEBUFFER, accumFbo_.id());
      glBindTextureUnit(MFR_TEX_AUX1, layers_[cur].id());
      glDisable(GL_DEPTH_TEST);
      glDisable(GL_BLEND);
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      stats_.overflowPixels = countSamples([&] { fullScreen(blend_); });
    }
  }

  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  if (!dump) {
    glBindTextureUnit(MFR_TEX_AUX1, accum_.id());
    final_.set("uBackground", ctx.background);
    ctx.timer.begin("final");
    fullScreen(final_);
    ctx.timer.end();
  }
  glBindVertexArray(0);

  stats_.overflow = stats_.fragmentsDropped > 0;
  // What is neither peeled nor behind the last layer lay at exactly a peeled layer's depth.
  const std::uint64_t ties =
      stats_.fragmentsGenerated - std::min(stats_.fragmentsGenerated, stats_.fragmentsStored + stats_.fragmentsDropped);
  stats_.bytesAllocated = kBytesPerPixel * static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_);
  stats_.bytesUsed = stats_.bytesAllocated;
  stats_.kMin = stats_.kMax = static_cast<std::uint32_t>(maxPasses_);
  stats_.notes.emplace_back("layers peeled", std::to_string(layersPeeled));
  stats_.notes.emplace_back("max_passes", std::to_string(maxPasses_));
  if (ties > 0) stats_.notes.emplace_back("depth ties", depthTiesNote(ties));
  stats_.notes.emplace_back("capture/resolve", "all passes run in resolve: peeling composites while it peels");
}

Stats DepthPeelingFrontToBack::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "none";  // passes are ordered by GL; an occlusion query per pass decides when to stop
  return s;
}

}  // namespace mfr
