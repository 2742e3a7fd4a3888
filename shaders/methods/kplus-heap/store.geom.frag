// k+-buffer with a per-pixel max-heap (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient,
// Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015): unsorted capture
// of the k nearest fragments with O(log k) insertion, sorted in the resolve pass.
//   MFR_KB_CULLING: a fragment not nearer than the root (the pixel's current maximum) is rejected
//     before it takes the lock.
// Colour writes are off.
#include "common/kbuffer_sync.glsl"
#include "common/kbuffer_store.glsl"
#include "common/kbuffer_maxheap.glsl"

uint kbPrepare() {
  if (gK == 0u) return KB_REJECT;
#ifdef MFR_KB_CULLING
  // Racy read of the root: +inf or a real maximum, never smaller than the true one.
  if (!(gDepth < kbDepth(kbEntries[kbSlot(0u)]))) return KB_REJECT;
#endif
  return KB_LOCK;
}

void kbInsert() { kbMaxHeapInsert(); }
