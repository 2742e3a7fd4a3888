#include "moment_based_oit.hpp"

#include <cmath>
#include <sstream>

#include "common/bindings.h"
#include "method_util.hpp"
#include "mfr/error.hpp"
#include "weighted_blended_oit.hpp"  // DepthMapping

namespace mfr {
namespace {
std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

const MethodInfo& MomentBasedOit::info() const {
  static const MethodInfo i{
      "mboit",
      "Moment-based order-independent transparency",
      "Münstermann, Krumpen, Klein, Peters: Moment-Based Order-Independent Transparency. "
      "Proc. ACM Comput. Graph. Interact. Tech. 1(1), 2018",
      false,
      {{"moments",
        "Power moments",
        ParamSpec::Type::Choice,
        "4",
        0,
        0,
        {"4", "6"},
        "number of power moments (single precision, 20 or 28 bytes per pixel)"},
       {"overestimation",
        "Overestimation",
        ParamSpec::Type::Float,
        "0.25",
        0,
        1,
        {},
        "blend between the lower (0) and upper (1) bound of the absorbance in front of a fragment"},
       {"bias",
        "Moment bias",
        ParamSpec::Type::Float,
        "-1",
        -1,
        0.5,
        {},
        "weight of the paper's bias moments; -1: the paper's value (5e-7 for 4, 5e-6 for 6 moments)"},
       {"warp",
        "Depth warp",
        ParamSpec::Type::Choice,
        "log",
        0,
        0,
        {"log", "linear"},
        "log: the paper's logarithmic warp of view depth (perspective only; orthographic views use "
        "linear); linear: view depth mapped linearly"}},
      "oit",
      false,
      false};
  return i;
}

std::uint64_t MomentBasedOit::bytesPerPixel(int moments) {
  return 4 + 16 + (moments == 6 ? 8 : 0) + 8;
}

double MomentBasedOit::paperBias(int moments) {
  return moments == 6 ? 5e-6 : 5e-7;
}

void MomentBasedOit::configure(int width, int height, const Params& params) {
  const int moments = params.text("moments") == "6" ? 6 : 4;
  overestimation_ = params.real("overestimation");
  const double bias = params.real("bias");
  bias_ = bias < 0.0 ? paperBias(moments) : bias;
  warp_ = params.text("warp");
  if (width != width_ || height != height_ || moments != moments_) {
    width_ = width;
    height_ = height;
    moments_ = moments;
    b0_ = gl::createTexture2D(GL_R32F, width, height);
    b1234_ = gl::createTexture2D(GL_RGBA32F, width, height);
    b56_ = moments == 6 ? gl::createTexture2D(GL_RG32F, width, height) : gl::Texture{};
    accum_ = gl::createTexture2D(GL_RGBA16F, width, height);
    momentsFbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(momentsFbo_.id(), GL_COLOR_ATTACHMENT0, b0_.id(), 0);
    glNamedFramebufferTexture(momentsFbo_.id(), GL_COLOR_ATTACHMENT1, b1234_.id(), 0);
    if (moments == 6) glNamedFramebufferTexture(momentsFbo_.id(), GL_COLOR_ATTACHMENT2, b56_.id(), 0);
    const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(momentsFbo_.id(), moments == 6 ? 3 : 2, buffers);
    accumFbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(accumFbo_.id(), GL_COLOR_ATTACHMENT0, accum_.id(), 0);
    glNamedFramebufferDrawBuffer(accumFbo_.id(), GL_COLOR_ATTACHMENT0);
    for (GLuint fbo : {momentsFbo_.id(), accumFbo_.id()})
      if (glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error("mboit", "moment framebuffer incomplete");
  }
  if (!samples_) samples_ = gl::createQuery(GL_SAMPLES_PASSED);
  if (!composite_.id())
    composite_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "methods/mboit/composite.screen.frag"}});
  programs();  // compile errors surface in configure, not mid-frame
}

MomentBasedOit::Programs& MomentBasedOit::programs() {
  auto it = programs_.find(moments_);
  if (it == programs_.end()) {
    const gl::Defines defines{{"MFR_MBOIT_M", std::to_string(moments_ / 2)}};
    Programs p;
    p.moments = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/mboit/moments.geom.frag"}}, defines);
    p.accumulate = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/mboit/accumulate.geom.frag"}}, defines);
    it = programs_.emplace(moments_, std::move(p)).first;
  }
  return it->second;
}

void MomentBasedOit::capture(const FrameContext& ctx) {
  stats_ = Stats{};
  Programs& p = programs();
  const DepthMapping depth = depthMapping(ctx.frame.viewProj);
  // The logarithm needs |z_eye| > 0 at the near plane: only a perspective view knows it.
  const bool logWarp = warp_ == "log" && depth.perspective && depth.nearDepth > 0.0f;
  const float lo = logWarp ? std::log(depth.nearDepth) : depth.nearDepth;
  const float hi = logWarp ? std::log(depth.farDepth) : depth.farDepth;
  const glm::vec2 warp(lo, 1.0f / std::max(hi - lo, 1e-30f));
  for (const gl::Program* program : {&p.moments, &p.accumulate}) {
    depth.bind(*program);
    program->set("uWarpLog", logWarp ? 1 : 0);
    program->set("uWarp", warp);
  }
  p.accumulate.set("uMomentBias", static_cast<float>(bias_));
  p.accumulate.set("uOverestimation", static_cast<float>(overestimation_));

  GLint previous = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous);
  const float zero[4] = {0, 0, 0, 0};
  for (GLint i = 0; i < (moments_ == 6 ? 3 : 2); ++i) glClearNamedFramebufferfv(momentsFbo_.id(), GL_COLOR, i, zero);
  glClearNamedFramebufferfv(accumFbo_.id(), GL_COLOR, 0, zero);
  {
    // Both passes only blend (no side effects): colour writes on, no depth test, no culling.
    GeometryPassState state(true, false);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, momentsFbo_.id());
    glBeginQuery(GL_SAMPLES_PASSED, samples_.id());
    ctx.timer.begin("moments");
    ctx.scene.draw(p.moments, ctx.frame);
    ctx.timer.end();
    glEndQuery(GL_SAMPLES_PASSED);

    // The next pass reads the moments as textures. They are no longer attached to the bound
    // framebuffer, so there is no feedback loop, and GL orders framebuffer writes before later
    // texture fetches by itself (barriers are only for image/SSBO stores).
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, accumFbo_.id());
    glBindTextureUnit(MFR_TEX_AUX0, b0_.id());
    glBindTextureUnit(MFR_TEX_AUX1, b1234_.id());
    glBindTextureUnit(MFR_TEX_AUX2, moments_ == 6 ? b56_.id() : 0);
    ctx.timer.begin("accumulate");
    ctx.scene.draw(p.accumulate, ctx.frame);
    ctx.timer.end();
    for (GLuint unit : {MFR_TEX_AUX0, MFR_TEX_AUX1, MFR_TEX_AUX2}) glBindTextureUnit(unit, 0);
    glBlendFunc(GL_ONE, GL_ZERO);
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(previous));

  GLuint64 samples = 0;
  glGetQueryObjectui64v(samples_.id(), GL_QUERY_RESULT, &samples);
  stats_.passes = 2;
  stats_.fragmentsGenerated = samples;
  const std::uint64_t bytes = static_cast<std::uint64_t>(width_) * height_ * bytesPerPixel(moments_);
  stats_.bytesAllocated = bytes;
  stats_.bytesUsed = bytes;
  stats_.notes.emplace_back("moments", std::to_string(moments_));
  stats_.notes.emplace_back("moment bias", number(bias_));
  stats_.notes.emplace_back("overestimation", number(overestimation_));
  stats_.notes.emplace_back("depth warp", logWarp             ? "log |z_eye|"
                                          : depth.perspective ? "linear |z_eye|"
                                                              : "linear (orthographic)");
}

void MomentBasedOit::resolve(const FrameContext& ctx, const Operation& op) {
  if (op.name != "oit")
    throw Error("--op " + op.name,
                "not supported by mboit (approximate moment-based OIT keeps no fragment lists; only oit)");
  glBindTextureUnit(MFR_TEX_AUX0, b0_.id());
  glBindTextureUnit(MFR_TEX_AUX1, accum_.id());
  runResolvePass(ctx, composite_, op);
  glBindTextureUnit(MFR_TEX_AUX0, 0);
  glBindTextureUnit(MFR_TEX_AUX1, 0);
}

Stats MomentBasedOit::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "none";  // fixed-function additive blending
  return s;
}

}  // namespace mfr
