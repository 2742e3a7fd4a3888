// k-buffer store-pass helpers shared by kbuffer (Bavoil et al., "Multi-fragment effects on the GPU
// using the k-buffer", I3D 2007) and the k+-buffer variants (Vasilakis, Papaioannou, Fudos, IEEE
// TVCG 21(6) 2015): the current fragment, its pixel's slots, statistics, and the default
// (non-revised) hooks of common/kbuffer_sync.glsl. Include after common/kbuffer_sync.glsl.
#include "common/fragment.glsl"
#include "common/kbuffer_array.glsl"

uvec2 gFrag;   // the current fragment's payload (colour, depth bits)
float gDepth;  // its depth
uint gPixel;   // its pixel index
uint gBase, gStride, gK;  // its pixel's slots: gBase + i * gStride, i < gK

uint kbSlot(uint i) { return gBase + i * gStride; }

void kbBegin() {
  MfrFragment f = mfrCurrentFragment();
  gFrag = mfrPack(f);
  gDepth = f.depth;
  gPixel = kbPixel(ivec2(gl_FragCoord.xy));
  gBase = kbBase(gPixel);
  gStride = kbStride(gPixel);
  gK = kbCapacity(gPixel);
  atomicAdd(kbGenerated, 1u);
}

void kbRejected() { kbNotKept(gPixel, gFrag); }
void kbLockFailed() { atomicAdd(kbLockFailures, 1u); }

#ifndef KB_CUSTOM_READY
bool kbReady() { return true; }
#endif
