#pragma once
// A-buffer with variable-length contiguous per-pixel arrays: S-buffer (Vasilakis & Fudos,
// Eurographics 2012 short papers). Count pass → compute-shader prefix sum (PrefixSum) → store
// pass → resolve. Shaders: shaders/methods/abuffer-sbuffer.
#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"
#include "prefix_sum.hpp"

namespace mfr {

class ABufferSBuffer final : public Method {
 public:
  static constexpr std::uint64_t kFragmentBytes = 8;
  static constexpr std::uint64_t kCounterBytes = 8;  // dropped fragments, overflowing pixels

  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

 private:
  void ensureCapacity(std::uint64_t fragments);

  int width_ = 0, height_ = 0;
  std::string sizing_ = "count";
  std::uint64_t fixedCapacity_ = 0;
  std::uint64_t capacity_ = 0;       // fragments the fragment buffer holds
  std::uint64_t previousTotal_ = 0;  // last frame's fragment count (sizing=previous)
  gl::Buffer counts_;                // width·height + 1 uints: counts, then store cursors
  gl::Buffer offsets_;               // width·height + 1 uints: exclusive scan of counts
  gl::Buffer fragments_;
  gl::Buffer counter_;
  PrefixSum scan_;
  gl::Program count_, store_;
  ResolveProgramCache resolve_;
  Stats stats_;
};

}  // namespace mfr
