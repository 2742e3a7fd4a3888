// k-buffer family storage: Bavoil, Callahan, Lefohn, Comba, Silva, "Multi-fragment effects on the
// GPU using the k-buffer", I3D 2007, and Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient,
// Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6), 2015.
// Shared by the store and resolve passes of kbuffer, kplus-array, kplus-heap, kplus-sbuffer and
// kplus-dynamic: k slots of the 8-byte payload per pixel, the global statistics counters and the
// optional tail accumulation (hybrid transparency hook).
//
// Layout: slot i of pixel p at kbEntries[uKbBase(p) + i * uKbStride(p)]. Fixed-k methods use
// slice-major order (base = p, stride = W*H: neighbouring pixels touch neighbouring words, which
// coalesces on GPUs); kplus-sbuffer overrides kbBase/kbStride through MFR_KB_VARIABLE (base = the
// pixel's prefix-sum offset, stride = 1). An empty slot holds depth +inf (KB_EMPTY): it compares
// greater than every fragment, so "insert if nearer than the maximum" needs no emptiness test, and
// a racy read of the maximum outside the critical section is either +inf or a real maximum.
#ifndef MFR_KBUFFER_ARRAY_GLSL
#define MFR_KBUFFER_ARRAY_GLSL
#include "common/bindings.h"
#include "common/payload.glsl"

#ifndef KB_ACCESS
#define KB_ACCESS coherent
#endif

layout(std430, binding = MFR_SSBO_NODES) KB_ACCESS buffer KBufferEntries { uvec2 kbEntries[]; };

// Frame statistics (read back by the C++ side): fragments rasterised, fragments that did not end
// among the pixel's k (culled, rejected or evicted), fragments dropped after spin_limit failed
// lock attempts.
layout(std430, binding = MFR_SSBO_COUNTER) buffer KBufferCounters {
  uint kbGenerated;
  uint kbNotKeptCount;
  uint kbLockFailures;
  uint kbReserved[5];
};

const uint KB_EMPTY = 0x7F800000u;  // float bits of +inf

uniform int uKbWidth;
uniform uint uKbPixels;  // W*H
uniform uint uKbK;       // capacity (fixed-k methods)

uint kbPixel(ivec2 p) { return uint(p.y) * uint(uKbWidth) + uint(p.x); }

#ifdef MFR_KB_VARIABLE
// kplus-sbuffer: per-pixel offsets (exclusive prefix sum of min(n(p), k)) and capacities.
layout(std430, binding = MFR_SSBO_OFFSETS) readonly buffer KBufferOffsets { uint kbOffsets[]; };
uint kbBase(uint pixel) { return kbOffsets[pixel]; }
uint kbStride(uint pixel) { return 1u; }
uint kbCapacity(uint pixel) { return kbOffsets[pixel + 1u] - kbOffsets[pixel]; }
#else
uint kbBase(uint pixel) { return pixel; }
uint kbStride(uint pixel) { return uKbPixels; }
uint kbCapacity(uint pixel) { return uKbK; }
#endif

float kbDepth(uvec2 e) { return uintBitsToFloat(e.y); }

// --- Tail accumulation: the fragments that do not end among the pixel's k nearest. ------------
// Per pixel five uints: Σ r·α, Σ g·α, Σ b·α (units of 1/255², exact integer products of the
// 8-bit values), Σ α (units of 1/255) and the count. Integer atomics make the sums exact and
// independent of the order fragments arrive in (GL 4.5 has no float atomics); they overflow only
// beyond 66051 tail fragments in one pixel, above MFR_MAX_LIST_WALK.
#ifdef MFR_KB_TAIL
layout(std430, binding = MFR_SSBO_TAIL) buffer KBufferTail { uint kbTail[]; };
void kbTailAdd(uint pixel, uint color) {
  uvec4 c = (uvec4(color) >> uvec4(0u, 8u, 16u, 24u)) & 0xFFu;
  uint base = 5u * pixel;
  atomicAdd(kbTail[base + 0u], c.r * c.a);
  atomicAdd(kbTail[base + 1u], c.g * c.a);
  atomicAdd(kbTail[base + 2u], c.b * c.a);
  atomicAdd(kbTail[base + 3u], c.a);
  atomicAdd(kbTail[base + 4u], 1u);
}
#else
void kbTailAdd(uint pixel, uint color) {}
#endif

// A fragment leaves (or never enters) the pixel's k nearest.
void kbNotKept(uint pixel, uvec2 e) {
  atomicAdd(kbNotKeptCount, 1u);
  kbTailAdd(pixel, e.x);
}

#endif
