// k-peeling (Bavoil et al., I3D 2007, multi-pass k-buffer) with the k+-buffer max-array and its
// per-pixel critical section (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015): store
// pass of one iteration. Keeps the k smallest keys (depth, object, primitive) strictly greater
// than the pixel's threshold (the largest key composited by the previous iterations). Slot 0
// holds the largest kept key; a fragment behind its depth is culled before the lock (a racy read
// of slot 0's depth is +inf or a real maximum's, never below the true one: conservative).
// Colour writes are off.
#include "common/kbuffer_sync.glsl"
#include "common/fragment.glsl"
#include "methods/kpeel/peel.glsl"

uvec4 gEntry;
uint gPixel;

void kbBegin() {
  MfrFragment f = mfrCurrentFragment();
  gEntry = uvec4(f.color, floatBitsToUint(f.depth), uObjectId, uint(gl_PrimitiveID));
  gPixel = kpPixel(ivec2(gl_FragCoord.xy));
}

uint kbPrepare() {
  uvec4 threshold = kpPixels[gPixel].threshold;
  if (threshold.w > 0u && !kpLess(threshold.xyz, kpKey(gEntry))) return KB_REJECT;  // composited already
  // k nearer ones held already. Only the depth word is read outside the lock: a single 32-bit word
  // cannot tear, and it never drops below the true maximum's depth; equal depths go on to the
  // full key comparison inside the critical section.
  if (uintBitsToFloat(gEntry.y) > uintBitsToFloat(kpEntries[kpSlot(gPixel, 0u)].y)) return KB_REJECT;
  return KB_LOCK;
}

bool kbReady() { return true; }
void kbRejected() {}
void kbLockFailed() { atomicAdd(kpLockFailures, 1u); }

// Max-array insertion by key: slot 0 = largest; a nearer fragment replaces it, then the largest
// of slots 1..k-1 and the fragment moves into slot 0 (written once, with its final value).
void kbInsert() {
  uvec4 top = kpEntries[kpSlot(gPixel, 0u)];
  if (!kpLess(kpKey(gEntry), kpKey(top))) return;
  uint far = 0u;
  uvec4 farEntry = gEntry;
  for (uint i = 1u; i < uKbK; ++i) {
    uvec4 e = kpEntries[kpSlot(gPixel, i)];
    if (kpLess(kpKey(farEntry), kpKey(e))) {
      far = i;
      farEntry = e;
    }
  }
  kpEntries[kpSlot(gPixel, 0u)] = farEntry;
  if (far != 0u) kpEntries[kpSlot(gPixel, far)] = gEntry;
}
