#pragma once
// Dynamic k for the k+-buffer (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient,
// Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015, eqs. 4-7): choose the
// per-frame k from the depth-complexity histogram, a memory budget M_b and a robustness ratio R_h.
// Pure CPU code (the histogram is built on the GPU by kplus-dynamic), unit-tested on hand-made
// histograms (tests/unit/test_dynamic_k.cpp).
//
// The rule as implemented (the paper's selection rule, eq. 6, with its inputs M_b and R_h from
// eqs. 4-7; the exact algebra below is ours, written down so it can be checked):
//   memory of a fixed-k structure           M(k) = P·(x·k + y) + z
//   largest k the budget holds               k_M = floor((M_b − z − P·y) / (P·x))
//   fragments captured with k                C(k) = Σ_n min(n, k)·h(n),  F = Σ_n n·h(n)
//   smallest k capturing R_h of them         k_R = min { k ≥ 1 : C(k) ≥ R_h·F }
//   chosen                                   k = min(k_R, k_M, k_max)
// so the budget is never exceeded; k = 0 means even k = 1 does not fit (the caller reports it).
#include <cstdint>
#include <span>
#include <string>

namespace mfr {

// Bytes of a fixed-k k-buffer: pixels·(bytesPerSlot·k + bytesPerPixel) + fixedBytes.
struct KBufferMemoryModel {
  std::uint64_t pixels = 0;
  std::uint64_t bytesPerSlot = 8;
  std::uint64_t bytesPerPixel = 0;
  std::uint64_t fixedBytes = 0;
  [[nodiscard]] std::uint64_t bytes(std::uint64_t k) const {
    return pixels * (bytesPerSlot * k + bytesPerPixel) + fixedBytes;
  }
};

struct DynamicKChoice {
  std::uint32_t k = 0;            // chosen; 0: the budget does not hold k = 1
  std::uint32_t kMemory = 0;      // k_M, capped at kMax
  std::uint32_t kRobust = 0;      // k_R, capped at kMax
  double capturedFraction = 1.0;  // C(k) / F with the chosen k (1 for an empty frame)
  std::uint64_t bytes = 0;        // M(k) for the chosen k
  std::string reason;             // which bound decided, in words (for Stats::notes)
};

// histogram[n]: pixels with exactly n fragments, except the last bin, which counts the pixels with
// n ≥ histogram.size() − 1 (their exact n only matters for F: pass totalFragments = Σ n(p), the
// count pass's exact total; 0 takes F from the histogram, the last bin counted at its index).
// robustness R_h in [0, 1]; kMax ≥ 1.
DynamicKChoice selectDynamicK(std::span<const std::uint64_t> histogram, std::uint64_t totalFragments,
                              std::uint64_t budgetBytes, double robustness, const KBufferMemoryModel& model,
                              std::uint32_t kMax = 256);

}  // namespace mfr
