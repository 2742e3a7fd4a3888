#pragma once
// Dynamic k+-buffer (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient, Memory-Friendly and
// Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015): every frame, a count pass and a compute
// pass build the depth-complexity histogram on the GPU; k is chosen from it, a memory budget M_b
// and a robustness ratio R_h (selectDynamicK, mfr/budget/dynamic_k.hpp); then the max-array or
// max-heap k+-buffer runs with that k. Shaders: shaders/methods/kplus-dynamic (count, histogram,
// resolve); the store pass is kplus-array's or kplus-heap's.
#include "kbuffer_common.hpp"
#include "mfr/budget/dynamic_k.hpp"

namespace mfr {

class KPlusBufferDynamic final : public KBufferFamily {
 public:
  static constexpr std::uint32_t kBins = 258;  // n = 0..256 exact, the last bin n >= 257

  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  // The memory model the budget is checked against (equals what capture allocates).
  [[nodiscard]] KBufferMemoryModel memoryModel() const;
  // The last frame's depth-complexity histogram as read back (kBins bins; tests check it).
  [[nodiscard]] const std::vector<std::uint64_t>& lastHistogram() const { return histogramRead_; }

 private:
  bool culling_ = true;
  std::string structure_ = "array";
  std::uint64_t budgetBytes_ = 0;
  std::string budgetText_;  // as given, for messages
  double robustness_ = 0.95;
  gl::Buffer counts_, histogram_;
  gl::Program count_, histogramPass_;
  DynamicKChoice choice_;
  std::vector<std::uint64_t> histogramRead_;
};

}  // namespace mfr
