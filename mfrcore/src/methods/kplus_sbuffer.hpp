#pragma once
// k+-buffer on S-buffer storage, K+B-AB_SB (Vasilakis, Papaioannou, Fudos, "k+-buffer: An
// Efficient, Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015, Alg. 3): a
// bounded count pass (counters stop at k), a prefix sum (PrefixSum) that allocates min(n(p), k)
// contiguous slots per pixel, then the max-array or max-heap store pass over those slots.
// Shaders: shaders/methods/kplus-sbuffer (count, resolve); the store pass is kplus-array's or
// kplus-heap's with MFR_KB_VARIABLE (variable per-pixel capacity).
#include "kbuffer_common.hpp"
#include "prefix_sum.hpp"

namespace mfr {

class KPlusBufferSBuffer final : public KBufferFamily {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  // min(n(p), k): differences of the prefix-sum offsets.
  [[nodiscard]] std::vector<std::uint32_t> capacityMap() const override;

 private:
  bool culling_ = true;
  std::string structure_ = "array";
  gl::Buffer counts_, offsets_;  // width·height + 1 uints each
  gl::Program count_;
  PrefixSum scan_;
};

}  // namespace mfr
