#include "kplus_array.hpp"

namespace mfr {

const MethodInfo& KPlusBufferMaxArray::info() const {
  static const MethodInfo i{"kplus-array", "k+-buffer, max-array",
                            "Vasilakis, Papaioannou, Fudos: k+-buffer: An Efficient, Memory-Friendly and Dynamic "
                            "k-buffer Framework. IEEE TVCG 21(6), 2015 (max-array)",
                            false, kbufferParams(true, true)};
  return i;
}

void KPlusBufferMaxArray::configure(int width, int height, const Params& params) {
  k_ = static_cast<std::uint32_t>(params.integer("k"));
  culling_ = params.flag("culling");
  revised_ = params.flag("revised");
  gl::Defines defines;
  if (culling_) defines.emplace("MFR_KB_CULLING", "1");
  if (revised_) defines.emplace("MFR_KB_REVISED", "1");
  configureCommon(width, height, params, "kplus-array", "kplus-array", defines);
  // Revised: per pixel two uints (fragments arrived, direct writes completed).
  allocateSlots(pixels() * k_, revised_ ? pixels() * 8 : 0);
}

void KPlusBufferMaxArray::capture(const FrameContext& ctx) {
  beginStore();
  drawStore(ctx);
  finishStore();
  stats_.notes.emplace_back("structure",
                            revised_ ? "max-array, revised (direct insertion of the first k-1)" : "max-array");
  stats_.notes.emplace_back("culling", culling_ ? "on" : "off");
}

}  // namespace mfr
