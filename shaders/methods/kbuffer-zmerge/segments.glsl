// k-buffer with z-thickness fragment merging — Kim & Kye, "Z-Thickness Blending: Effective Fragment
// Merging for Multi-Fragment Rendering", Computer Graphics Forum 40(7) 2021: storage shared by the
// store and resolve passes. Each of a pixel's k slots holds a ray segment [front, back] (eye depths)
// of uniform medium: optical depth D = ∫σ (a fragment's own: -ln(1 - α)) and colour c (the
// D-weighted mean of what was merged into it). 12 bytes, as in the paper: front (float bits),
// ((back - front) / T, D) as a half pair, c as RGBA8. The length is kept in units of the thickness
// T: a half holds at most 65504 and nothing below 6e-8, so lengths in scene units lost every
// segment of a scene larger than 6.5e6 (the default T is 1 % of its diagonal) or of a tiny T; a
// fragment's own slab is exactly 1, and a merge spanning more than 65504·T is cut there. Slot i of pixel p is segment i·P + p (slice-major,
// as the k-buffers), words 3·segment … 3·segment + 2; used slots are 0..m-1, an empty slot has
// front = +inf.
#include "common/bindings.h"

// ZM_READONLY: the resolve pass only reads the segments.
#ifdef ZM_READONLY
#define ZM_ACCESS readonly
#else
#define ZM_ACCESS coherent
#endif
layout(std430, binding = MFR_SSBO_NODES) ZM_ACCESS buffer ZMergeSegments { uint zmWords[]; };

uniform int uZmWidth;
uniform uint uZmPixels;
uniform uint uZmK;
uniform float uZmThickness;  // T: the unit of the stored lengths

const uint ZM_EMPTY = 0x7F800000u;  // float bits of +inf

struct Segment {
  float front, back;
  float opticalDepth;
  vec3 color;
};

uint zmPixel(ivec2 p) { return uint(p.y) * uint(uZmWidth) + uint(p.x); }
uint zmSlot(uint pixel, uint i) { return i * uZmPixels + pixel; }
bool zmEmpty(uint slot) { return zmWords[3u * slot] == ZM_EMPTY; }

Segment zmLoad(uint slot) {
  float front = uintBitsToFloat(zmWords[3u * slot]);
  vec2 lengthDepth = unpackHalf2x16(zmWords[3u * slot + 1u]);
  return Segment(front, front + lengthDepth.x * uZmThickness, lengthDepth.y,
                 unpackUnorm4x8(zmWords[3u * slot + 2u]).rgb);
}

#ifndef ZM_READONLY
void zmStore(uint slot, Segment s) {
  zmWords[3u * slot] = floatBitsToUint(s.front);
  zmWords[3u * slot + 1u] = packHalf2x16(vec2(min((s.back - s.front) / uZmThickness, 65504.0), s.opticalDepth));
  zmWords[3u * slot + 2u] = packUnorm4x8(vec4(s.color, 0.0));
}
#endif
