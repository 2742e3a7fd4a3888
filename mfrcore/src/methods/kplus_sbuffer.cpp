#include "kplus_sbuffer.hpp"

#include "common/bindings.h"
#include "method_util.hpp"

namespace mfr {

const MethodInfo& KPlusBufferSBuffer::info() const {
  static const MethodInfo i = [] {
    std::vector<ParamSpec> params = kbufferParams(true, false);
    params.push_back({"structure",
                      "Per-pixel structure",
                      ParamSpec::Type::Choice,
                      "array",
                      0,
                      0,
                      {"array", "heap"},
                      "max-array or max-heap over the pixel's min(n, k) slots"});
    return MethodInfo{"kplus-sbuffer", "k+-buffer on S-buffer storage (memory-aware)",
                      "Vasilakis, Papaioannou, Fudos: k+-buffer: An Efficient, Memory-Friendly and Dynamic k-buffer "
                      "Framework. IEEE TVCG 21(6), 2015 (K+B-AB_SB, Alg. 3)",
                      false, params};
  }();
  return i;
}

void KPlusBufferSBuffer::configure(int width, int height, const Params& params) {
  k_ = static_cast<std::uint32_t>(params.integer("k"));
  culling_ = params.flag("culling");
  structure_ = params.text("structure");
  gl::Defines defines{{"MFR_KB_VARIABLE", "1"}};
  if (culling_) defines.emplace("MFR_KB_CULLING", "1");
  resolveDefines_ = {{"MFR_KB_VARIABLE", "1"}};
  const bool resized = width != width_ || height != height_;
  configureCommon(width, height, params, structure_ == "heap" ? "kplus-heap" : "kplus-array", "kplus-sbuffer", defines);
  if (resized || !counts_) {
    counts_ = gl::createBuffer((pixels() + 1) * 4);
    offsets_ = gl::createBuffer((pixels() + 1) * 4);
  }
  if (!count_.id())
    count_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/kplus-sbuffer/count.geom.frag"}});
}

void KPlusBufferSBuffer::capture(const FrameContext& ctx) {
  // Bounded count pass: min(n(p), k) per pixel; the extra last element stays 0, so the exclusive
  // scan's last offset is the total.
  const GLuint zero = 0;
  glClearNamedBufferData(counts_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  {
    GeometryPassState state;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, counts_.id());
    setCommonUniforms(count_);
    ctx.timer.begin("count");
    ctx.scene.draw(count_, ctx.frame);
    ctx.timer.end();
  }
  ctx.timer.begin("prefix sum");
  scan_.scan(counts_.id(), offsets_.id(), static_cast<std::uint32_t>(pixels() + 1));
  ctx.timer.end();
  const std::uint32_t total = scan_.readTotal();  // exact allocation: Σ min(n(p), k) slots

  allocateSlots(total, 0);
  beginStore();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, offsets_.id());
  drawStore(ctx);
  finishStore(2 * (pixels() + 1) * 4 + scan_.bytesAllocated());
  stats_.passes += 1;  // the count pass
  stats_.kMin = 0;
  stats_.notes.emplace_back("structure", structure_ == "heap" ? "max-heap" : "max-array");
  stats_.notes.emplace_back("culling", culling_ ? "on" : "off");
  stats_.notes.emplace_back("slots", std::to_string(total) + " = sum of min(n(p), k)");
}

void KPlusBufferSBuffer::resolve(const FrameContext& ctx, const Operation& op) {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, offsets_.id());
  KBufferFamily::resolve(ctx, op);
}

}  // namespace mfr

namespace mfr {

std::vector<std::uint32_t> KPlusBufferSBuffer::capacityMap() const {
  return readCapacities(offsets_, pixels());
}

}  // namespace mfr
