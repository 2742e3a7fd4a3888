// Classic k-buffer (Bavoil, Callahan, Lefohn, Comba, Silva, "Multi-fragment effects on the GPU
// using the k-buffer", I3D 2007), done correctly: the original read-modify-write of the pixel's
// depth-SORTED k entries raced on hardware without per-pixel synchronisation; here the insertion
// runs inside the per-pixel critical section of the k+-buffer (common/kbuffer_sync.glsl).
// Insertion sort step: shift the entries farther than the new fragment one slot back (the last
// one, if real, leaves the k nearest) and write the fragment into the gap. Equal depths keep
// arrival order (a fragment goes behind the entries it ties with). Colour writes are off.
#include "common/kbuffer_sync.glsl"
#include "common/kbuffer_store.glsl"

uint kbPrepare() { return gK == 0u ? KB_REJECT : KB_LOCK; }

void kbInsert() {
  uvec2 last = kbEntries[kbSlot(gK - 1u)];
  if (!(gDepth < kbDepth(last))) {  // not among the k nearest
    kbNotKept(gPixel, gFrag);
    return;
  }
  if (last.y != KB_EMPTY) kbNotKept(gPixel, last);  // evicted
  uint j = gK - 1u;
  for (; j > 0u; --j) {  // at most k - 1 moves
    uvec2 previous = kbEntries[kbSlot(j - 1u)];
    if (!(kbDepth(previous) > gDepth)) break;
    kbEntries[kbSlot(j)] = previous;
  }
  kbEntries[kbSlot(j)] = gFrag;
}
