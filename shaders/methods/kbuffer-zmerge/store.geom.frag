// k-buffer with z-thickness fragment merging (Kim & Kye, "Z-Thickness Blending: Effective Fragment
// Merging for Multi-Fragment Rendering", Computer Graphics Forum 40(7) 2021): store pass. Each
// fragment becomes the slab [z, z + T] behind its surface (T = uZThickness, eye depths); while the
// pixel has a free slot it is stored as it is, and once the k slots are full the two segments —
// among the k stored and the new one — that overlap most (or, if none overlap, the two farthest)
// are merged into one: their union, optical depths added (so the pixel's total opacity is kept
// exactly), colours averaged by optical depth. Nothing is ever dropped. The read-modify-write
// of a pixel's slots runs in the k+-buffer's per-pixel critical section (common/kbuffer_sync.glsl:
// Vasilakis & Fudos, I3D 2014, Alg. 1; bounded spin lock). Colour writes are off.
#include "common/kbuffer_sync.glsl"
#include "common/fragment.glsl"
#include "methods/kbuffer-zmerge/segments.glsl"

layout(std430, binding = MFR_SSBO_COUNTER) buffer ZMergeCounters {
  uint zmGenerated;     // fragments rasterised
  uint zmMerges;        // merges made (each frees one slot)
  uint zmLockFailures;  // fragments dropped after uSpinLimit failed lock attempts
  uint zmTransparent;   // fragments with α = 0 (nothing to store)
  uint zmReserved[4];
};

#include "common/eye_depth.glsl"
uniform float uZThickness;

Segment gSegment;  // the current fragment's slab
uint gPixel;

void kbBegin() {
  MfrFragment f = mfrCurrentFragment();
  vec4 c = unpackUnorm4x8(f.color);
  float z = mfrEyeDepth(f.depth);
  gSegment = Segment(z, z + uZThickness, -log(1.0 - min(c.a, float(MFR_ZTHICK_MAX_ALPHA))), vec3(c));
  gPixel = zmPixel(ivec2(gl_FragCoord.xy));
  atomicAdd(zmGenerated, 1u);
}

uint kbPrepare() { return gSegment.opticalDepth > 0.0 ? KB_LOCK : KB_REJECT; }
bool kbReady() { return true; }
void kbRejected() { atomicAdd(zmTransparent, 1u); }
void kbLockFailed() { atomicAdd(zmLockFailures, 1u); }

// Depth distance between two segments: negative when they overlap (minus the overlap's length).
float zmGap(Segment a, Segment b) { return max(a.front, b.front) - min(a.back, b.back); }

Segment zmMerge(Segment a, Segment b) {
  float d = a.opticalDepth + b.opticalDepth;
  vec3 c = (a.opticalDepth * a.color + b.opticalDepth * b.color) / d;
  return Segment(min(a.front, b.front), max(a.back, b.back), d, c);
}

void kbInsert() {
  Segment s[MFR_ZMERGE_MAX_K + 1];
  uint used = 0u;
  for (uint i = 0u; i < uZmK; ++i) {
    if (zmEmpty(zmSlot(gPixel, i))) break;
    s[i] = zmLoad(zmSlot(gPixel, i));
    ++used;
  }
  if (used < uZmK) {
    zmStore(zmSlot(gPixel, used), gSegment);
    return;
  }
  s[used] = gSegment;
  // The pair to merge: the two that overlap most; if none overlap, the two farthest (by front),
  // so the nearest segments — which the eye sees first — stay as captured (first pair on ties).
  uint bi = 0u, bj = 1u;
  float best = 0.0;
  for (uint i = 0u; i < used; ++i)
    for (uint j = i + 1u; j <= used; ++j) {
      float g = zmGap(s[i], s[j]);
      if (g < best) {
        best = g;
        bi = i;
        bj = j;
      }
    }
  if (!(best < 0.0)) {
    // No overlap: the farthest (f1) and second farthest (f2) fronts.
    uint f1 = 0u, f2 = 1u;
    if (s[1].front > s[0].front) {
      f1 = 1u;
      f2 = 0u;
    }
    for (uint i = 2u; i <= used; ++i) {
      if (s[i].front > s[f1].front) {
        f2 = f1;
        f1 = i;
      } else if (s[i].front > s[f2].front) {
        f2 = i;
      }
    }
    bi = min(f1, f2);
    bj = max(f1, f2);
  }
  zmStore(zmSlot(gPixel, bi), zmMerge(s[bi], s[bj]));
  if (bj < used) zmStore(zmSlot(gPixel, bj), gSegment);  // the new one takes the freed slot
  atomicAdd(zmMerges, 1u);
}
