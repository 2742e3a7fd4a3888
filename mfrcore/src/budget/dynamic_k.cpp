#include "mfr/budget/dynamic_k.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mfr {

DynamicKChoice selectDynamicK(std::span<const std::uint64_t> histogram, std::uint64_t totalFragments,
                              std::uint64_t budgetBytes, double robustness, const KBufferMemoryModel& model,
                              std::uint32_t kMax) {
  DynamicKChoice c;
  kMax = std::max<std::uint32_t>(kMax, 1);
  robustness = std::clamp(robustness, 0.0, 1.0);

  // k_M from the budget (exact integer arithmetic, never above it).
  const std::uint64_t base = model.bytes(0);
  const std::uint64_t perK = model.pixels * model.bytesPerSlot;
  std::uint64_t kM = 0;
  if (budgetBytes >= base) kM = perK > 0 ? (budgetBytes - base) / perK : kMax;
  c.kMemory = static_cast<std::uint32_t>(std::min<std::uint64_t>(kM, kMax));

  // F and C(k): the last bin holds n >= last index; min(n, k) = k there whenever k <= last index.
  const std::size_t bins = histogram.size();
  std::uint64_t fromHistogram = 0;
  for (std::size_t n = 0; n < bins; ++n) fromHistogram += n * histogram[n];
  const std::uint64_t f = totalFragments > 0 ? totalFragments : fromHistogram;
  const auto captured = [&](std::uint64_t k) {
    std::uint64_t sum = 0;
    for (std::size_t n = 0; n < bins; ++n) sum += std::min<std::uint64_t>(n, k) * histogram[n];
    return std::min(sum, f);
  };
  // k_R: smallest k with C(k) >= R_h·F. C is non-decreasing in k, so scan upwards.
  // A relative 1e-12 slack: R_h given as a decimal (0.8) must not miss an exact boundary by rounding.
  const long double need = static_cast<long double>(robustness) * static_cast<long double>(f) * (1.0L - 1e-12L);
  std::uint32_t kR = 1;
  while (kR < kMax && static_cast<long double>(captured(kR)) < need) ++kR;
  c.kRobust = kR;

  // The smaller bound decides.
  c.k = std::min(c.kRobust, c.kMemory);
  std::ostringstream why;
  if (c.k == 0) {
    why << "memory budget " << budgetBytes << " B holds no k >= 1 (k = 1 needs " << model.bytes(1) << " B)";
  } else {
    c.bytes = model.bytes(c.k);
    c.capturedFraction = f > 0 ? static_cast<double>(captured(c.k)) / static_cast<double>(f) : 1.0;
    if (c.kRobust <= c.kMemory)
      why << "robustness: k = " << c.k << " captures " << c.capturedFraction * 100.0
          << " % of the fragments (R_h = " << robustness * 100.0 << " %); the budget would allow k = " << c.kMemory;
    else
      why << "memory budget: k = " << c.k << " (" << c.bytes << " of " << budgetBytes << " B) captures "
          << c.capturedFraction * 100.0 << " % of the fragments; R_h = " << robustness * 100.0
          << " % needs k = " << c.kRobust;
  }
  c.reason = why.str();
  return c;
}

}  // namespace mfr
