#pragma once
// The memory budget of variable-k hybrid transparency (Tsopouridis, Fudos, Vasilakis, "Deep
// hybrid order-independent transparency", The Visual Computer 2022, eq. 1): the number of
// fragment slots F(M) a budget of M bytes holds once the per-pixel and fixed parts of the
// structure are paid for, from the bytes our k+-buffer max-array really allocates
// (KBufferFamily's constants, mfrcore/src/methods/kbuffer_common.hpp):
//   M(k) = P·(x·k + y) + z            x = 8 (RGBA8 + float depth per slot)
//   y = 4 (spin-lock semaphore; 0 with interlock) + 20 (tail sums, tail on) + 8 (revised counters)
//   z = 32 (statistics counters)
//   F(M) = floor((M − z − P·y) / x), 0 when M does not hold the fixed parts
//   fkb(M) = min(floor(F(M) / P), 256): the largest uniform k whose buffers fit in M.
#include <cstdint>

#include "mfr/budget/dynamic_k.hpp"

namespace mfr {

struct KPlusArrayLayout {
  bool tail = true;       // --param tail
  bool spinLock = true;   // --param sync=spinlock (the interlock needs no semaphore image)
  bool revised = false;   // --param revised (two per-pixel counters)
};

// x, y, z of the kplus-array method for `pixels` pixels.
KBufferMemoryModel kplusArrayMemoryModel(std::uint64_t pixels, const KPlusArrayLayout& layout = {});

// F(M): fragment slots that fit in budgetBytes (0 when not even the fixed parts fit).
std::uint64_t slotBudget(const KBufferMemoryModel& model, std::uint64_t budgetBytes);

// fkb: the largest uniform k (≤ kMax) with model.bytes(k) ≤ budgetBytes; 0 when k = 1 does not fit.
std::uint32_t largestUniformK(const KBufferMemoryModel& model, std::uint64_t budgetBytes, std::uint32_t kMax = 256);

}  // namespace mfr
