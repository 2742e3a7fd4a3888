#pragma once
// From per-pixel importance to per-pixel k under a slot budget F — the rule the variable-k
// buffers (vkb, dkb) share, here on the CPU, bit for bit what their GPU passes compute
// (shaders/budget/allocation.h states it; docs/methods.md explains it):
//   * k(p) = 0 where n(p) = 0; 1 ≤ k(p) ≤ n(p) elsewhere when F holds one slot per non-empty
//     pixel (else 0 ≤ k(p): the least important pixels keep only the weighted-average tail);
//   * with exactTail (the default), k(p) ≤ e(p) while F ≤ Σ e, and k(p) ≥ e(p) above it, where
//     e(p) = max(1, n(p) − m(p)) and m(p) = 1, or, given tail runs, the length of the pixel's final
//     run of fragments of one colour: hybrid transparency composites such a tail exactly, so no
//     slot goes to a fragment of it while another pixel could use the slot;
//   * Σk(p) ≤ F, and Σk(p) = min(F, Σn(p)): the budget is used up;
//   * k grows with importance: k(p) = clamp(floor(λ·I(p)), lower(p), upper(p)) for the largest λ
//     that fits, plus one more slot for the first pixels (in pixel order) that grow just above it.
#include <cstdint>
#include <span>
#include <vector>

namespace mfr {

struct ImportanceAllocation {
  std::vector<std::uint32_t> k;  // per pixel
  std::uint64_t assigned = 0;    // Σk
  std::uint32_t kFloor = 1;      // 1, or 0 when F < non-empty pixels
  float lambdaLow = 0.0f;        // the search's final interval [λ_lo, λ_hi]
  float lambdaHigh = 0.0f;
};

// The bounds of k(p) for F slots over an image with nonEmpty pixels with n > 0 and
// exactSlots = Σ e(p) (Σ max(1, n − 1) = total − (pixels with n > 1) without tail runs): the mode
// word of shaders/budget/allocation.h (MFR_ALLOC_* bits) and S(0) = Σ_p lower(p), where the λ
// search starts.
struct AllocationBounds {
  std::uint32_t mode = 0;
  std::uint64_t sumAtZero = 0;
};
AllocationBounds allocationBounds(std::uint64_t F, std::uint64_t nonEmpty, std::uint64_t exactSlots, bool exactTail,
                                  bool tailRuns = false);

// importance and n have one entry per pixel (any order; the tie-break follows it), and so has
// tailRuns, the final run length m(p) of each pixel (mfr::tailRunLengths), when given; empty
// means m = 1 everywhere. Importances that are NaN, negative or below the floor count as the
// floor. Throws mfr::Error when the sizes differ.
ImportanceAllocation allocateKFromImportance(std::span<const float> importance, std::span<const std::uint32_t> n,
                                             std::uint64_t budgetSlots, bool exactTail = true,
                                             std::span<const std::uint32_t> tailRuns = {});

}  // namespace mfr
