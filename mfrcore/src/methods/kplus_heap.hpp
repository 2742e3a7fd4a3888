#pragma once
// k+-buffer with per-pixel max-heaps (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient,
// Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015): unsorted capture
// of the k nearest fragments with O(log k) insertion and culling against the root before the lock.
// Shaders: shaders/methods/kplus-heap.
#include "kbuffer_common.hpp"

namespace mfr {

class KPlusBufferMaxHeap final : public KBufferFamily {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;

 private:
  bool culling_ = true;
};

}  // namespace mfr
