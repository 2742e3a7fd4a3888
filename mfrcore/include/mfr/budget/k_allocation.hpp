#pragma once
// From per-pixel importance to per-pixel k under a slot budget F — the rule the variable-k
// buffers (vkb, dkb) share, here on the CPU, bit for bit what their GPU passes compute
// (shaders/budget/allocation.h states it; docs/methods.md explains it):
//   * k(p) = 0 where n(p) = 0; 1 ≤ k(p) ≤ n(p) elsewhere when F holds one slot per non-empty
//     pixel (else 0 ≤ k(p): the least important pixels keep only the weighted-average tail);
//   * Σk(p) ≤ F, and Σk(p) = min(F, Σn(p)): the budget is used up;
//   * k grows with importance: k(p) = clamp(floor(λ·I(p)), k_floor, n(p)) for the largest λ that
//     fits, plus one more slot for the first pixels (in pixel order) that grow just above it.
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

// importance and n have one entry per pixel (any order; the tie-break follows it). Importances
// that are NaN, negative or below the floor count as the floor. Throws mfr::Error when the sizes
// differ.
ImportanceAllocation allocateKFromImportance(std::span<const float> importance, std::span<const std::uint32_t> n,
                                             std::uint64_t budgetSlots);

}  // namespace mfr
