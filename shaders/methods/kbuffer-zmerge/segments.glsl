// k-buffer with z-thickness fragment merging — Kim & Kye, "Z-Thickness Blending: Effective Fragment
// Merging for Multi-Fragment Rendering", Computer Graphics Forum 40(7) 2021: storage shared by the
// store and resolve passes. Each of a pixel's k slots holds a ray segment [front, back] (eye depths)
// of uniform medium: optical depth D = ∫σ (a fragment's own: -ln(1 - α)) and colour c (the
// D-weighted mean of what was merged into it). 16 bytes: front, back (float bits), (c.r, c.g),
// (c.b, D) as half pairs. Slot i of pixel p at zmSegments[i·P + p] (slice-major, as the k-buffers);
// used slots are 0..m-1, an empty slot has front = +inf.
#include "common/bindings.h"

#ifndef ZM_ACCESS
#define ZM_ACCESS coherent
#endif
layout(std430, binding = MFR_SSBO_NODES) ZM_ACCESS buffer ZMergeSegments { uvec4 zmSegments[]; };

uniform int uZmWidth;
uniform uint uZmPixels;
uniform uint uZmK;

const uint ZM_EMPTY = 0x7F800000u;  // float bits of +inf

struct Segment {
  float front, back;
  float opticalDepth;
  vec3 color;
};

uint zmPixel(ivec2 p) { return uint(p.y) * uint(uZmWidth) + uint(p.x); }
uint zmSlot(uint pixel, uint i) { return i * uZmPixels + pixel; }

Segment zmUnpack(uvec4 v) {
  vec2 rg = unpackHalf2x16(v.z), bd = unpackHalf2x16(v.w);
  return Segment(uintBitsToFloat(v.x), uintBitsToFloat(v.y), bd.y, vec3(rg, bd.x));
}

uvec4 zmPack(Segment s) {
  return uvec4(floatBitsToUint(s.front), floatBitsToUint(s.back), packHalf2x16(s.color.rg),
               packHalf2x16(vec2(s.color.b, s.opticalDepth)));
}
