#pragma once
// fkb: the fixed k-buffer under a memory budget M — the baseline of the deep hybrid OIT paper
// (Tsopouridis, Fudos, Vasilakis, The Visual Computer 2022): the largest uniform k whose
// k+-buffer max-array (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015) with the tail sums
// fits in M, from the bytes it really allocates (mfr/budget/memory_model.hpp). Shaders: the store
// pass of kplus-array; shaders/methods/fkb (resolve).
#include "kbuffer_common.hpp"

namespace mfr {

class FixedKBuffer final : public KBufferFamily {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;

 private:
  bool culling_ = true;
  std::string budgetText_;
  std::uint64_t budgetBytes_ = 0;
  bool blockCapped_ = false;  // k held to what the largest storage block holds, below the budget's
};

}  // namespace mfr
