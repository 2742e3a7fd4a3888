#include "kplus_heap.hpp"

namespace mfr {

const MethodInfo& KPlusBufferMaxHeap::info() const {
  static const MethodInfo i{"kplus-heap", "k+-buffer, max-heap",
                            "Vasilakis, Papaioannou, Fudos: k+-buffer: An Efficient, Memory-Friendly and Dynamic "
                            "k-buffer Framework. IEEE TVCG 21(6), 2015 (max-heap)",
                            false, kbufferParams(true, false)};
  return i;
}

void KPlusBufferMaxHeap::configure(int width, int height, const Params& params) {
  k_ = static_cast<std::uint32_t>(params.integer("k"));
  culling_ = params.flag("culling");
  gl::Defines defines;
  if (culling_) defines.emplace("MFR_KB_CULLING", "1");
  configureCommon(width, height, params, "kplus-heap", "kplus-heap", defines);
  allocateSlots(pixels() * k_, 0);
}

void KPlusBufferMaxHeap::capture(const FrameContext& ctx) {
  beginStore();
  drawStore(ctx);
  finishStore();
  stats_.notes.emplace_back("structure", "max-heap");
  stats_.notes.emplace_back("culling", culling_ ? "on" : "off");
}

}  // namespace mfr
