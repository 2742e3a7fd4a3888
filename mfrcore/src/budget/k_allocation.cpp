// The variable-k allocation rule on the CPU (shaders/budget/allocation.h, the same search the GPU
// passes shaders/budget/alloc_*.comp run): a reference for tests and for optimal-k's neighbours.
#include "mfr/budget/k_allocation.hpp"

#include <algorithm>
#include <bit>
#include <string>

#include "budget/glsl_shared.hpp"
#include "mfr/error.hpp"

namespace mfr {

namespace {

std::uint64_t sumAt(std::uint32_t lambdaBits, std::span<const float> importance, std::span<const std::uint32_t> n,
                    std::span<const std::uint32_t> e, std::uint32_t mode) {
  const float lambda = std::bit_cast<float>(lambdaBits);
  std::uint64_t s = 0;
  for (std::size_t p = 0; p < n.size(); ++p) s += glsl::mfrAllocK(lambda, importance[p], n[p], e[p], mode);
  return s;
}

}  // namespace

AllocationBounds allocationBounds(std::uint64_t F, std::uint64_t nonEmpty, std::uint64_t exactSlots, bool exactTail,
                                  bool tailRuns) {
  const bool floorOne = F >= nonEmpty;
  AllocationBounds b{floorOne ? MFR_ALLOC_FLOOR_ONE : 0u, floorOne ? nonEmpty : 0u};
  if (!exactTail) return b;
  if (tailRuns) b.mode |= MFR_ALLOC_RUNS;
  if (F <= exactSlots) {
    b.mode |= MFR_ALLOC_CAP_TAIL;
  } else {
    b.mode |= MFR_ALLOC_FILL;
    b.sumAtZero = exactSlots;  // lower = e(p) everywhere
  }
  return b;
}

ImportanceAllocation allocateKFromImportance(std::span<const float> rawImportance, std::span<const std::uint32_t> n,
                                             std::uint64_t budgetSlots, bool exactTail,
                                             std::span<const std::uint32_t> tailRuns) {
  if (rawImportance.size() != n.size())
    throw Error("importance map",
                std::to_string(rawImportance.size()) + " entries for " + std::to_string(n.size()) + " pixels");
  if (!tailRuns.empty() && tailRuns.size() != n.size())
    throw Error("tail-run map",
                std::to_string(tailRuns.size()) + " entries for " + std::to_string(n.size()) + " pixels");
  std::vector<float> importance(rawImportance.size());
  std::transform(rawImportance.begin(), rawImportance.end(), importance.begin(), glsl::mfrSanitizeImportance);

  const bool runs = exactTail && !tailRuns.empty();
  std::vector<std::uint32_t> e(n.size());
  std::uint64_t total = 0, nonEmpty = 0, exactSlots = 0;
  for (std::size_t p = 0; p < n.size(); ++p) {
    e[p] = glsl::mfrAllocExactK(n[p], runs ? tailRuns[p] : 1u);
    total += n[p];
    nonEmpty += n[p] > 0;
    exactSlots += e[p];
  }
  ImportanceAllocation out;
  const AllocationBounds bounds = allocationBounds(budgetSlots, nonEmpty, exactSlots, exactTail, runs);
  const std::uint32_t mode = bounds.mode;
  out.kFloor = (mode & MFR_ALLOC_FLOOR_ONE) != 0u ? 1u : 0u;

  // Invariant S(lo) ≤ F < S(hi), or lo = hi = +inf when every fragment fits.
  std::uint32_t lo = 0, hi = MFR_ALLOC_INFINITY_BITS;
  std::uint64_t sLo = bounds.sumAtZero;
  if (total <= budgetSlots) {
    lo = hi;
    sLo = total;
  }
  for (std::uint32_t round = 0; round < MFR_ALLOC_ROUNDS; ++round) {
    std::uint32_t newLo = lo, newHi = hi;
    std::uint64_t newSLo = sLo;
    for (std::uint32_t j = 1; j < MFR_ALLOC_SECTIONS; ++j) {
      const std::uint32_t c = glsl::mfrAllocCandidate(lo, hi, j);
      const std::uint64_t s = sumAt(c, importance, n, e, mode);
      if (s <= budgetSlots) {
        newLo = c;
        newSLo = s;
      } else {
        newHi = c;
        break;  // S grows with λ: every later candidate is over too
      }
    }
    lo = newLo;
    hi = newHi;
    sLo = newSLo;
  }

  const float lambdaLo = std::bit_cast<float>(lo), lambdaHi = std::bit_cast<float>(hi);
  std::uint64_t remaining = budgetSlots > sLo ? budgetSlots - sLo : 0;
  out.k.resize(n.size());
  for (std::size_t p = 0; p < n.size(); ++p) {
    const std::uint32_t kLo = glsl::mfrAllocK(lambdaLo, importance[p], n[p], e[p], mode);
    const std::uint32_t kHi = glsl::mfrAllocK(lambdaHi, importance[p], n[p], e[p], mode);
    const std::uint64_t extra = std::min<std::uint64_t>(remaining, kHi - kLo);
    remaining -= extra;
    out.k[p] = kLo + static_cast<std::uint32_t>(extra);
    out.assigned += out.k[p];
  }
  out.lambdaLow = lambdaLo;
  out.lambdaHigh = lambdaHi;
  return out;
}

}  // namespace mfr
