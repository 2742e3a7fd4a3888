#pragma once
// What the variable k-buffers share — vkb (Vasilakis, Vardis, Papaioannou, Moustakas, "Variable
// k-buffer using Importance Maps", EG 2017 Short Papers) and dkb (Tsopouridis, Fudos, Vasilakis,
// "Deep hybrid order-independent transparency", The Visual Computer 2022): under a memory budget
// M every frame
//   1. feature passes (the member's): n(p) and what its importance needs, into the arena;
//   2. image sums (compute), read back once: Σn and the non-empty pixels fix F = min(F(M), Σn)
//      and the size of the slot buffer;
//   3. importance I(p) (the member's compute pass);
//   3b. with tail_runs: three geometry passes find each pixel's final run of m(p) fragments of
//      one colour (shaders/budget/tail_run_*), and Σ max(1, n − m) is read back;
//   4. allocation (compute, shaders/budget/alloc_*.comp, two prefix sums): k(p) by the shared
//      rule of mfr/budget/k_allocation.hpp — 1 ≤ k(p) ≤ n(p), Σk = F, no slot for a
//      fragment of an exactly composited tail while another pixel lacks one;
//   5. the k+-buffer max-array store into each pixel's k(p) contiguous slots (spin lock on arena
//      words or interlock), fragments beyond k(p) into the tail sums;
//   6. resolve (hybrid: core + tail, or oit: core only).
// Memory: mfr/budget/memory_model.hpp's VariableKLayout; Stats.bytesAllocated ≤ M always.
#include <string>

#include "kbuffer_common.hpp"
#include "mfr/budget/memory_model.hpp"
#include "prefix_sum.hpp"

namespace mfr {

class VariableKBuffer : public KBufferFamily {
 public:
  void configure(int width, int height, const Params& params) final;
  void capture(const FrameContext& ctx) final;
  void resolve(const FrameContext& ctx, const Operation& op) final;
  [[nodiscard]] std::vector<std::uint32_t> capacityMap() const final;

  // The budget parameters every variable-k method has (budget_mib, sync, spin_limit, culling,
  // exact_tail, tail_runs).
  static std::vector<ParamSpec> budgetParams();
  [[nodiscard]] const VariableKLayout& layout() const { return layout_; }
  // Per-pixel importance of the last frame (GL row order), read back from the arena: valid only
  // between computeImportance and the allocation, so it is captured there when keepImportance.
  void setKeepImportance(bool keep) { keepImportance_ = keep; }
  [[nodiscard]] const std::vector<float>& lastImportance() const { return importance_; }
  [[nodiscard]] const std::vector<std::uint32_t>& lastCounts() const { return counts_; }
  // m(p) of the last frame's tail-run passes (GL row order; empty when tail_runs was off), also
  // only kept with keepImportance.
  [[nodiscard]] const std::vector<std::uint32_t>& lastTailRuns() const { return tailRunMap_; }

 protected:
  // Member hooks. Shader folder, its configure, its fixed GPU bytes besides the shared ones.
  [[nodiscard]] virtual std::string folder() const = 0;
  virtual void configureMember(const Params& params) = 0;
  [[nodiscard]] virtual std::uint64_t memberFixedBytes() const { return 0; }
  // Clears the feature regions the member's passes accumulate into (after N was cleared).
  virtual void clearFeatures() = 0;
  // Geometry passes filling N(p) and the member's features (GeometryPassState is set, the arena
  // bound); returns how many it drew.
  virtual std::uint32_t drawFeatures(const FrameContext& ctx) = 0;
  [[nodiscard]] virtual bool needsDepthRange() const { return false; }
  // The T(i) region in which drawFeatures leaves each pixel's farthest depth (float bits, 0 where
  // empty) for the tail-run passes; it must survive computeImportance, and i must be 1 or 2
  // (T(0) holds the importance, T(3), T(4) and K are the passes' own).
  [[nodiscard]] virtual std::uint32_t farthestDepthRegion() const = 0;
  // Compute pass writing I(p) into T(0).
  virtual void computeImportance(const FrameContext& ctx) = 0;
  [[nodiscard]] virtual std::string describeImportance() const = 0;

  // Arena uniforms for a program of this method.
  void setArenaUniforms(const gl::Program& program) const;
  void bindArena() const;
  // Clears `words` words at word offset `base` of the arena to `value`.
  void clearArena(std::uint64_t base, std::uint64_t words, std::uint32_t value) const;
  // Dispatches program over the pixels, `groupSize` invocations per group, on a 2D grid.
  void dispatchPixels(const gl::Program& program, std::uint32_t groupSize) const;

  VariableKLayout layout_;
  gl::Buffer arena_, state_;
  std::uint64_t budgetBytes_ = 0;
  std::string budgetText_;

 private:
  void allocate(const FrameContext& ctx);
  // The tail-run passes; returns Σ max(1, n − m).
  std::uint64_t findTailRuns(const FrameContext& ctx);

  bool culling_ = true;
  bool exactTail_ = true;
  bool tailRuns_ = true;
  bool keepImportance_ = false;
  std::vector<float> importance_;
  std::vector<std::uint32_t> counts_, tailRunMap_;
  gl::Program imageStats_, search_, narrow_, assign_, finish_;
  gl::Program runColor_, runBreak_, runLength_, runSum_;
  PrefixSum scan_;
  std::uint64_t slotsF_ = 0;  // F of the last frame
  std::uint64_t totalFragments_ = 0, nonEmpty_ = 0;
};

}  // namespace mfr
