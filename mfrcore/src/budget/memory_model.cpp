// F(M) of the deep hybrid OIT paper (The Visual Computer 2022, eq. 1) from the bytes the
// k+-buffer max-array allocates (KBufferFamily, methods/kbuffer_common.hpp).
#include "mfr/budget/memory_model.hpp"

#include <algorithm>

#include "methods/kbuffer_common.hpp"
#include "methods/prefix_sum.hpp"

namespace mfr {

KBufferMemoryModel kplusArrayMemoryModel(std::uint64_t pixels, const KPlusArrayLayout& layout) {
  KBufferMemoryModel m;
  m.pixels = pixels;
  m.bytesPerSlot = KBufferFamily::kEntryBytes;
  m.bytesPerPixel =
      (layout.spinLock ? 4 : 0) + (layout.tail ? KBufferFamily::kTailBytesPerPixel : 0) + (layout.revised ? 8 : 0);
  m.fixedBytes = KBufferFamily::kCounterBytes;
  return m;
}

std::uint64_t slotBudget(const KBufferMemoryModel& model, std::uint64_t budgetBytes) {
  const std::uint64_t fixed = model.pixels * model.bytesPerPixel + model.fixedBytes;
  if (budgetBytes <= fixed || model.bytesPerSlot == 0) return 0;
  return (budgetBytes - fixed) / model.bytesPerSlot;
}

std::uint32_t largestUniformK(const KBufferMemoryModel& model, std::uint64_t budgetBytes, std::uint32_t kMax) {
  if (model.pixels == 0) return kMax;
  const std::uint64_t k = slotBudget(model, budgetBytes) / model.pixels;
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(k, kMax));
}

VariableKLayout variableKLayout(std::uint64_t pixels, std::uint64_t extraFixedBytes) {
  const auto align = [](std::uint64_t words) { return (words + 63) / 64 * 64; };  // 256 bytes
  VariableKLayout l;
  l.pixels = pixels;
  l.lockBase = 0;
  l.tailBase = align(pixels);
  l.stride = align(pixels + 1);  // a T region also holds the scans' W·H + 1 elements
  l.kBase = l.tailBase + 5 * l.stride;
  l.arenaWords = l.kBase + align(pixels + 1);
  l.scanScratchBytes = 4 * PrefixSum::scratchElements(pixels + 1);
  l.fixedBytes = KBufferFamily::kCounterBytes + kVariableKStateBytes + extraFixedBytes;
  return l;
}

}  // namespace mfr
