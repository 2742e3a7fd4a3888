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
  bool tail = true;      // --param tail
  bool spinLock = true;  // --param sync=spinlock (the interlock needs no semaphore image)
  bool revised = false;  // --param revised (two per-pixel counters)
};

// x, y, z of the kplus-array method for `pixels` pixels.
KBufferMemoryModel kplusArrayMemoryModel(std::uint64_t pixels, const KPlusArrayLayout& layout = {});

// F(M): fragment slots that fit in budgetBytes (0 when not even the fixed parts fit).
std::uint64_t slotBudget(const KBufferMemoryModel& model, std::uint64_t budgetBytes);

// fkb: the largest uniform k (≤ kMax) with model.bytes(k) ≤ budgetBytes; 0 when k = 1 does not fit.
std::uint32_t largestUniformK(const KBufferMemoryModel& model, std::uint64_t budgetBytes, std::uint32_t kMax = 256);

// The variable-k buffers (vkb, dkb; mfrcore/src/methods/variable_k_buffer.hpp) keep every
// per-pixel value in one arena of 32-bit words reused from pass to pass, so a budget pays for the
// largest phase only: per pixel 1 word (n(p), then the spin lock), 5 words (features and
// importance, then the tail sums) and 1 word (k(p), then the store's offsets), each region
// starting on a 256-byte boundary so the store pass can bind it as its own buffer range. Besides:
// the prefix-sum scratch for W·H + 1 elements, 32 bytes of statistics counters, 128 bytes of
// budget state and the method's fixed extras (dkb: the network's weights). Then
//   M(F) = 8·F + arena + scratch + fixed,   F(M) = floor((M − arena − scratch − fixed) / 8).
struct VariableKLayout {
  std::uint64_t pixels = 0;
  std::uint64_t lockBase = 0, tailBase = 0, stride = 0, kBase = 0, arenaWords = 0;  // words
  std::uint64_t scanScratchBytes = 0;
  std::uint64_t fixedBytes = 0;
  [[nodiscard]] std::uint64_t arenaBytes() const { return 4 * arenaWords; }
  [[nodiscard]] std::uint64_t bytesBeforeSlots() const { return arenaBytes() + scanScratchBytes + fixedBytes; }
  [[nodiscard]] std::uint64_t bytes(std::uint64_t slots) const { return 8 * slots + bytesBeforeSlots(); }
  // F(M): 0 when not even the per-pixel and fixed parts fit.
  [[nodiscard]] std::uint64_t slotBudget(std::uint64_t budgetBytes) const {
    return budgetBytes > bytesBeforeSlots() ? (budgetBytes - bytesBeforeSlots()) / 8 : 0;
  }
};
inline constexpr std::uint64_t kVariableKStateBytes = 128;
VariableKLayout variableKLayout(std::uint64_t pixels, std::uint64_t extraFixedBytes = 0);

}  // namespace mfr
