// Operation "dump" (tests and diagnostics, not a published method): writes each pixel's sorted
// fragments and its count to buffers, so every method's capture can be compared with the
// oracle's exact lists fragment by fragment.
layout(std430, binding = MFR_SSBO_DUMP) writeonly buffer DumpFragments { uvec2 dumpFragments[]; };
layout(std430, binding = MFR_SSBO_DUMP_COUNT) writeonly buffer DumpCounts { uint dumpCounts[]; };
uniform uint uDumpMax;  // fragments kept per pixel
uniform int uDumpWidth;

struct OpState {
  uint base;
};

void opBegin(inout OpState s, ivec2 pixel) { s.base = (uint(pixel.y) * uint(uDumpWidth) + uint(pixel.x)) * uDumpMax; }

void opFragment(inout OpState s, MfrFragment f, uint position) {
  if (position < uDumpMax) dumpFragments[s.base + position] = mfrPack(f);
}

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) {
  dumpCounts[uint(pixel.y) * uint(uDumpWidth) + uint(pixel.x)] = count;
  return vec4(0.0);
}
