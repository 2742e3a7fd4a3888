// k+-buffer with a per-pixel max-array (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient,
// Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015; I3D 2014 Alg. 1):
// unsorted capture of the k nearest fragments, sorted later in the resolve pass.
//   MFR_KB_CULLING: a fragment not nearer than the pixel's current maximum (slot 0) is rejected
//     before it takes the lock (most fragments of deep pixels, once the k slots are full).
//   MFR_KB_REVISED (§3.2.1): the first k-1 fragments of a pixel need no maximum search; a
//     per-pixel atomic counter gives each its own slot (k-1, k-2, …, 1). With the spin lock they
//     are written without taking the lock at all; a second per-pixel counter ("ready") is
//     incremented after each direct write (behind a memoryBarrier), and the fragments that do
//     need the critical section wait until all k-1 direct writes are visible (kbReady, inside the
//     bounded spin loop: a direct writer never waits for anything, so this cannot deadlock).
//     With interlock the counter is kept inside the critical section instead (interlock does not
//     order writes made outside it).
// Colour writes are off.
#include "common/kbuffer_sync.glsl"
#ifdef MFR_KB_REVISED
#define KB_CUSTOM_READY
#endif
#include "common/kbuffer_store.glsl"
#include "common/kbuffer_maxarray.glsl"

#ifdef MFR_KB_REVISED
// Per pixel: [2p] fragments that arrived, [2p+1] direct writes completed.
layout(std430, binding = MFR_SSBO_AUX) coherent buffer KBufferArrival { uint kbArrival[]; };
#endif

bool kbCulled() {
#ifdef MFR_KB_CULLING
  // Racy read of the current maximum: +inf or a real maximum, never smaller than the true one.
  return !(gDepth < kbDepth(kbEntries[kbSlot(0u)]));
#else
  return false;
#endif
}

#if defined(MFR_KB_REVISED) && !defined(MFR_SYNC_INTERLOCK)
uint kbPrepare() {
  if (gK == 0u) return KB_REJECT;
  uint arrival = atomicAdd(kbArrival[2u * gPixel], 1u);
  if (arrival + 1u < gK) {  // one of the first k-1: direct insertion, no lock
    kbEntries[kbSlot(gK - 1u - arrival)] = gFrag;
    memoryBarrier();
    atomicAdd(kbArrival[2u * gPixel + 1u], 1u);
    return KB_DONE;
  }
  return kbCulled() ? KB_REJECT : KB_LOCK;
}
// The critical section may read slots 1..k-1 only once every direct write has landed.
bool kbReady() { return atomicAdd(kbArrival[2u * gPixel + 1u], 0u) + 1u >= gK; }
void kbInsert() { kbMaxArrayInsert(); }
#elif defined(MFR_KB_REVISED)
uint kbPrepare() { return gK == 0u ? KB_REJECT : (kbCulled() ? KB_REJECT : KB_LOCK); }
bool kbReady() { return true; }
void kbInsert() {
  uint arrival = kbArrival[2u * gPixel];
  if (arrival + 1u < gK) {
    kbArrival[2u * gPixel] = arrival + 1u;
    kbEntries[kbSlot(gK - 1u - arrival)] = gFrag;
    return;
  }
  kbMaxArrayInsert();
}
#else
uint kbPrepare() { return gK == 0u ? KB_REJECT : (kbCulled() ? KB_REJECT : KB_LOCK); }
void kbInsert() { kbMaxArrayInsert(); }
#endif
