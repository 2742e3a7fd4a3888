#include "kbuffer.hpp"

namespace mfr {

const MethodInfo& KBufferSorted::info() const {
  static const MethodInfo i{"kbuffer", "k-buffer, sorted array in a critical section",
                            "Bavoil, Callahan, Lefohn, Comba, Silva: Multi-fragment effects on the GPU using the "
                            "k-buffer. I3D 2007",
                            false, kbufferParams(false, false)};
  return i;
}

void KBufferSorted::configure(int width, int height, const Params& params) {
  k_ = static_cast<std::uint32_t>(params.integer("k"));
  configureCommon(width, height, params, "kbuffer", "kbuffer", {});
  allocateSlots(pixels() * k_, 0);
}

void KBufferSorted::capture(const FrameContext& ctx) {
  beginStore();
  drawStore(ctx);
  finishStore();
  stats_.notes.emplace_back("structure", "sorted array (insertion in the critical section)");
}

}  // namespace mfr
