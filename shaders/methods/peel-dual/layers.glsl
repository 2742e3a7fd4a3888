// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Per-pixel state shared by the passes:
// - the depth range of the layers a pass peels, as (−nearest, farthest) in RG32F so that one MAX
//   blend finds both ends at once; an empty range is (−2, −2): nearest 2 > farthest −2;
// - the peeled front and back layer colours, RGBA32F (front.lo, front.hi, back.lo, back.hi): the
//   packed RGBA8 colour split into 16-bit halves, which floats hold exactly, so MAX blending
//   against the −1 every other fragment writes keeps the one writer's bits.
#include "common/bindings.h"
#include "common/payload.glsl"

const float PEEL_EMPTY = -2.0;

bool rangeEmpty(vec2 range) { return -range.x > range.y; }
vec2 colorToHalves(uint c) { return vec2(float(c & 0xFFFFu), float(c >> 16u)); }
uint halvesToColor(vec2 h) { return uint(h.x) | (uint(h.y) << 16u); }
