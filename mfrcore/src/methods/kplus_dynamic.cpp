#include "kplus_dynamic.hpp"

#include <algorithm>
#include <cmath>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {

const MethodInfo& KPlusBufferDynamic::info() const {
  static const MethodInfo i = [] {
    std::vector<ParamSpec> params = kbufferParams(true, false);
    std::erase_if(params, [](const ParamSpec& p) { return p.name == "k"; });  // chosen per frame
    params.push_back({"budget_mib",
                      "Memory budget M_b (MiB)",
                      ParamSpec::Type::Float,
                      "64",
                      0,
                      65536,
                      {},
                      "GPU memory the method may allocate for a frame (all its buffers)",
                      true});
    params.push_back({"robustness",
                      "Robustness ratio R_h",
                      ParamSpec::Type::Float,
                      "0.95",
                      0,
                      1,
                      {},
                      "fraction of the frame's fragments to capture: k is the smallest that captures it, "
                      "unless the budget allows less"});
    params.push_back({"structure",
                      "Per-pixel structure",
                      ParamSpec::Type::Choice,
                      "array",
                      0,
                      0,
                      {"array", "heap"},
                      "max-array or max-heap"});
    return MethodInfo{"kplus-dynamic", "k+-buffer, dynamic k from the depth-complexity histogram",
                      "Vasilakis, Papaioannou, Fudos: k+-buffer: An Efficient, Memory-Friendly and Dynamic k-buffer "
                      "Framework. IEEE TVCG 21(6), 2015 (dynamic k)",
                      false, params};
  }();
  return i;
}

void KPlusBufferDynamic::configure(int width, int height, const Params& params) {
  culling_ = params.flag("culling");
  structure_ = params.text("structure");
  budgetBytes_ = static_cast<std::uint64_t>(std::floor(params.real("budget_mib") * 1024.0 * 1024.0));
  budgetText_ = params.text("budget_mib");
  robustness_ = params.real("robustness");
  gl::Defines defines;
  if (culling_) defines.emplace("MFR_KB_CULLING", "1");
  const bool resized = width != width_ || height != height_;
  configureCommon(width, height, params, structure_ == "heap" ? "kplus-heap" : "kplus-array", "kplus-dynamic", defines);
  if (resized || !counts_) counts_ = gl::createBuffer(pixels() * 4);
  if (!histogram_) histogram_ = gl::createBuffer(kBins * 4);
  if (!count_.id()) {
    count_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/kplus-dynamic/count.geom.frag"}});
    histogramPass_ = gl::Program({{GL_COMPUTE_SHADER, "methods/kplus-dynamic/histogram.comp"}},
                                 {{"KD_BINS", std::to_string(kBins)}});
  }
}

KBufferMemoryModel KPlusBufferDynamic::memoryModel() const {
  KBufferMemoryModel m;
  m.pixels = pixels();
  m.bytesPerSlot = kEntryBytes;
  // per pixel: n(p) counter, semaphore (spin lock only), tail sums (tail on)
  m.bytesPerPixel = 4 + (sync_.name == "spinlock" ? 4 : 0) + (tail_ ? kTailBytesPerPixel : 0);
  m.fixedBytes = kCounterBytes + kBins * 4;
  return m;
}

void KPlusBufferDynamic::capture(const FrameContext& ctx) {
  // 1. n(p) per pixel and the exact total.
  const GLuint zero = 0;
  glClearNamedBufferData(counts_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearNamedBufferData(histogram_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearNamedBufferData(counters_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  {
    GeometryPassState state;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, counts_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counters_.id());
    setCommonUniforms(count_);
    ctx.timer.begin("count");
    ctx.scene.draw(count_, ctx.frame);
    ctx.timer.end();
  }
  // 2. Depth-complexity histogram (compute pass), read back: 258 bins + the total.
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, histogram_.id());
  histogramPass_.use();
  histogramPass_.set("uPixels", static_cast<unsigned>(pixels()));
  ctx.timer.begin("histogram");
  // On a 2D grid: glDispatchCompute takes at most 65535 groups a dimension (GL_INVALID_VALUE at
  // 4096x4096 and above; a review).
  const std::uint64_t groups = (pixels() + 255) / 256;
  const auto groupsX = static_cast<GLuint>(std::min<std::uint64_t>(groups, 65535));
  glDispatchCompute(groupsX, static_cast<GLuint>((groups + groupsX - 1) / groupsX), 1);
  ctx.timer.end();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> bins(kBins);
  glGetNamedBufferSubData(histogram_.id(), 0, kBins * 4, bins.data());
  std::uint32_t total = 0;
  glGetNamedBufferSubData(counters_.id(), 0, 4, &total);
  histogramRead_.assign(bins.begin(), bins.end());
  const std::vector<std::uint64_t>& histogram = histogramRead_;

  // 3. k from the histogram, the budget and R_h (eqs. 4-7).
  choice_ = selectDynamicK(histogram, total, budgetBytes_, robustness_, memoryModel(), 256);
  if (choice_.k == 0) {
    throw Error("--param budget_mib=" + budgetText_, choice_.reason);
  }
  k_ = choice_.k;

  // 4. The k+-buffer with that k.
  allocateSlots(pixels() * k_, 0);
  beginStore();
  drawStore(ctx);
  finishStore(pixels() * 4 + kBins * 4);
  stats_.passes += 1;  // the count pass
  stats_.notes.emplace_back("k chosen", choice_.reason);
  stats_.notes.emplace_back("k_M (budget)", std::to_string(choice_.kMemory));
  stats_.notes.emplace_back("k_R (robustness)", std::to_string(choice_.kRobust));
  stats_.notes.emplace_back("structure", structure_ == "heap" ? "max-heap" : "max-array");
  stats_.notes.emplace_back("culling", culling_ ? "on" : "off");
}

}  // namespace mfr
