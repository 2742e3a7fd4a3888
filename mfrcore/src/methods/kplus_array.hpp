#pragma once
// k+-buffer with per-pixel max-arrays (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient,
// Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015, §3.2 and §3.2.1; I3D 2014
// "k+-buffer: Fragment Synchronized k-buffer"): unsorted capture of the k nearest fragments with
// the maximum in slot 0, culling against it before the lock, optional direct insertion of the
// first k-1 fragments. Shaders: shaders/methods/kplus-array.
#include "kbuffer_common.hpp"

namespace mfr {

class KPlusBufferMaxArray final : public KBufferFamily {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;

 private:
  bool culling_ = true, revised_ = false;
};

}  // namespace mfr
