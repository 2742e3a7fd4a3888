#pragma once
// From per-pixel importance to per-pixel k under a slot budget F — the rule the variable-k
// buffers (vkb, dkb) share, here on the CPU, bit for bit what their GPU passes compute
// (shaders/budget/allocation.h states it; docs/methods.md explains it):
//   * k(p) = 0 where n(p) = 0; 1 ≤ k(p) ≤ n(p) elsewhere when F holds one slot per non-empty
//     pixel (else 0 ≤ k(p): the least important pixels keep only the weighted-average tail);
//   * with exactTail (the default), k(p) ≤ max(1, n(p) − 1) while F ≤ Σ max(1, n − 1), and
//     k(p) ≥ max(1, n(p) − 1) above it: a one-fragment tail is exact under hybrid transparency,
//     so no slot goes to a pixel's last fragment while another pixel could use it;
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

// The bounds of k(p) for F slots over an image with Σn = total, nonEmpty pixels with n > 0 and
// multi pixels with n > 1 (so Σ max(1, n − 1) = total − multi): the mode word of
// shaders/budget/allocation.h (MFR_ALLOC_* bits) and S(0) = Σ_p lower(p), where the λ search starts.
struct AllocationBounds {
  std::uint32_t mode = 0;
  std::uint64_t sumAtZero = 0;
};
AllocationBounds allocationBounds(std::uint64_t F, std::uint64_t total, std::uint64_t nonEmpty, std::uint64_t multi,
                                  bool exactTail);

// importance and n have one entry per pixel (any order; the tie-break follows it). Importances
// that are NaN, negative or below the floor count as the floor. Throws mfr::Error when the sizes
// differ.
ImportanceAllocation allocateKFromImportance(std::span<const float> importance, std::span<const std::uint32_t> n,
                                             std::uint64_t budgetSlots, bool exactTail = true);

}  // namespace mfr
