// k-peeling: multipass k-buffer (Bavoil et al., "Multi-fragment effects on the GPU using the
// k-buffer", I3D 2007: the multi-pass k-buffer, k layers peeled per geometry pass; Liu et al.,
// "Multi-layer depth peeling via fragment sort", 2009). Storage shared by its passes.
//
// Entries are 16 bytes: colour, depth bits, object id, primitive id. The (object, primitive) pair
// identifies a fragment within its pixel (a triangle covers a pixel centre at most once), so
// fragments are totally ordered by the key (depth, object, primitive): each iteration keeps the k
// smallest keys strictly greater than the previous iteration's largest, and fragments at EQUAL
// depth are never skipped or composited twice when a tie group straddles an iteration boundary.
#include "common/bindings.h"
#include "common/payload.glsl"

#ifndef KP_ACCESS
#define KP_ACCESS coherent
#endif

layout(std430, binding = MFR_SSBO_NODES) KP_ACCESS buffer KPeelEntries { uvec4 kpEntries[]; };

// Per pixel: the last composited key (depth bits, object, primitive) and the number of fragments
// composited so far (w; 0: no threshold yet); the OIT state carried between iterations (colour,
// transmittance). All-zero is the initial state, so one buffer clear resets it.
struct KPeelPixel {
  uvec4 threshold;
  vec4 accum;
};

// The transmittance carried in accum.a, as the operation left it: carried as opacity 1 - T, its
// float rounding there and back put a few pixels 1/255 off the A-buffers' image (a review). Before
// any fragment is composited (w = 0, the cleared state) it is 1.
float kpTransmittance(KPeelPixel pixelState) { return pixelState.threshold.w == 0u ? 1.0 : pixelState.accum.a; }
layout(std430, binding = MFR_SSBO_AUX) buffer KPeelPixels { KPeelPixel kpPixels[]; };

layout(std430, binding = MFR_SSBO_COUNTER) buffer KPeelCounters {
  uint kpGenerated;     // count pass: fragments rasterised
  uint kpMaxCount;      // count pass: largest n(p)
  uint kpCaptured;      // fragments composited over all iterations
  uint kpLockFailures;  // fragments dropped after spin_limit failed lock attempts
  uint kpReserved[4];
};

const uint KP_EMPTY = 0x7F800000u;  // depth +inf: an empty slot, greater than every key

uniform int uKbWidth;
uniform uint uKbPixels;
uniform uint uKbK;

uint kpPixel(ivec2 p) { return uint(p.y) * uint(uKbWidth) + uint(p.x); }
uint kpSlot(uint pixel, uint i) { return i * uKbPixels + pixel; }

// Strict key order; depths compared as floats (empty slots hold +inf).
bool kpLess(uvec3 a, uvec3 b) {
  float da = uintBitsToFloat(a.x), db = uintBitsToFloat(b.x);
  if (da != db) return da < db;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}
uvec3 kpKey(uvec4 entry) { return entry.yzw; }
