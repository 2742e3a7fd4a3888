#include "weighted_blended_oit.hpp"

#include <cmath>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {

DepthMapping depthMapping(const glm::mat4& viewProj) {
  // glm is column-major: m[column][row].
  const glm::vec4 row2(viewProj[0][2], viewProj[1][2], viewProj[2][2], viewProj[3][2]);
  const glm::vec4 row3(viewProj[0][3], viewProj[1][3], viewProj[2][3], viewProj[3][3]);
  const glm::vec3 r2(row2), r3(row3);
  DepthMapping m;
  const float r3len2 = glm::dot(r3, r3);
  if (r3len2 > 1e-12f) {
    // Perspective: row3 = −v (v = V's depth row), row2 = a·v + b·e4 with v.w = −row3.w.
    m.perspective = true;
    m.a = -glm::dot(r2, r3) / r3len2;
    m.b = row2.w + m.a * row3.w;
    m.nearDepth = m.b / (m.a - 1.0f);
    m.farDepth = m.b / (m.a + 1.0f);
  } else {
    // Orthographic: row2.xyz = a·v.xyz with |v.xyz| = 1 and a = −2/(f − n) < 0 for near < far.
    m.perspective = false;
    m.a = std::max(glm::length(r2), 1e-30f);
    m.b = 0.0f;
    m.nearDepth = 0.0f;
    m.farDepth = 2.0f / m.a;
  }
  return m;
}

void DepthMapping::bind(const gl::Program& program) const {
  program.set("uPerspective", perspective ? 1 : 0);
  program.set("uDepthMap", glm::vec2(a, b));
}

const MethodInfo& WeightedBlendedOit::info() const {
  static const MethodInfo i{
      "wboit",
      "Weighted blended order-independent transparency",
      "McGuire, Bavoil: Weighted Blended Order-Independent Transparency. JCGT 2(2), 2013",
      false,
      {{"weight",
        "Weight function",
        ParamSpec::Type::Choice,
        "eq7",
        0,
        0,
        {"eq7", "eq8", "eq9", "eq10", "none"},
        "the paper's depth weights w(z, α): eq7–eq9 of view depth |z| (tuned for 0.1 ≤ |z| ≤ 500 scene units), "
        "eq10 of window depth; none: w = 1 (plain weighted average)"},
       {"revealage",
        "Revealage format",
        ParamSpec::Type::Choice,
        "r8",
        0,
        0,
        {"r8", "r16f"},
        "render target of the revealage product Π(1 − α): r8 as in the paper, or r16f"}},
      "oit",
      false,
      false};
  return i;
}

std::uint64_t WeightedBlendedOit::bytesPerPixel(const std::string& revealageFormat) {
  return 8 + (revealageFormat == "r16f" ? 2 : 1);
}

void WeightedBlendedOit::configure(int width, int height, const Params& params) {
  weight_ = params.text("weight");
  const std::string revealage = params.text("revealage");
  if (width != width_ || height != height_ || revealage != revealageFormat_) {
    width_ = width;
    height_ = height;
    revealageFormat_ = revealage;
    accum_ = gl::createTexture2D(GL_RGBA16F, width, height);
    revealage_ = gl::createTexture2D(revealage == "r16f" ? GL_R16F : GL_R8, width, height);
    fbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT0, accum_.id(), 0);
    glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT1, revealage_.id(), 0);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(fbo_.id(), 2, buffers);
    if (glCheckNamedFramebufferStatus(fbo_.id(), GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("wboit", "accumulation framebuffer incomplete");
  }
  if (!samples_) samples_ = gl::createQuery(GL_SAMPLES_PASSED);
  if (!composite_.id())
    composite_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "methods/wboit/composite.screen.frag"}});
  accumulateProgram();  // compile errors surface in configure, not mid-frame
}

const gl::Program& WeightedBlendedOit::accumulateProgram() {
  auto it = accumulate_.find(weight_);
  if (it == accumulate_.end()) {
    const std::string number = weight_ == "none" ? "0" : weight_.substr(2);
    it = accumulate_
             .emplace(weight_, gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"},
                                            {GL_FRAGMENT_SHADER, "methods/wboit/accumulate.geom.frag"}},
                                           {{"MFR_WBOIT_WEIGHT", number}}))
             .first;
  }
  return it->second;
}

void WeightedBlendedOit::capture(const FrameContext& ctx) {
  stats_ = Stats{};
  GLint previous = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous);
  const float zero[4] = {0, 0, 0, 0}, one[4] = {1, 1, 1, 1};
  glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 0, zero);
  glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 1, one);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_.id());

  const DepthMapping depth = depthMapping(ctx.frame.viewProj);
  const gl::Program& program = accumulateProgram();
  depth.bind(program);
  {
    // Colour writes on (this pass only blends, no side effects), no depth test, no culling.
    GeometryPassState state(true, false);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunci(0, GL_ONE, GL_ONE);
    glBlendFunci(1, GL_ZERO, GL_ONE_MINUS_SRC_COLOR);
    // Fragments generated, counted without side effects: no depth test, so every one passes.
    glBeginQuery(GL_SAMPLES_PASSED, samples_.id());
    ctx.timer.begin("accumulate");
    ctx.scene.draw(program, ctx.frame);
    ctx.timer.end();
    glEndQuery(GL_SAMPLES_PASSED);
    glBlendFunc(GL_ONE, GL_ZERO);
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(previous));

  GLuint64 samples = 0;
  glGetQueryObjectui64v(samples_.id(), GL_QUERY_RESULT, &samples);
  stats_.passes = 1;
  stats_.fragmentsGenerated = samples;
  const std::uint64_t bytes = static_cast<std::uint64_t>(width_) * height_ * bytesPerPixel(revealageFormat_);
  stats_.bytesAllocated = bytes;
  stats_.bytesUsed = bytes;
  stats_.notes.emplace_back("weight", weight_);
  stats_.notes.emplace_back("revealage", revealageFormat_);
  if (weight_ == "eq7" || weight_ == "eq8" || weight_ == "eq9")
    stats_.notes.emplace_back(
        "view depth", depth.perspective ? "|z_eye| (perspective)" : "distance behind the near plane (orthographic)");
}

void WeightedBlendedOit::resolve(const FrameContext& ctx, const Operation& op) {
  if (op.name != "oit")
    throw Error("--op " + op.name,
                "not supported by wboit (approximate blended OIT keeps no fragment lists; only oit)");
  glBindTextureUnit(MFR_TEX_AUX0, accum_.id());
  glBindTextureUnit(MFR_TEX_AUX1, revealage_.id());
  runResolvePass(ctx, composite_, op);
  glBindTextureUnit(MFR_TEX_AUX0, 0);
  glBindTextureUnit(MFR_TEX_AUX1, 0);
}

Stats WeightedBlendedOit::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "none";  // fixed-function additive/multiplicative blending
  return s;
}

}  // namespace mfr
