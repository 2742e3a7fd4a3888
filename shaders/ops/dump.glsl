// Operation "dump" (tests and diagnostics, not a published method): writes each pixel's sorted
// fragments and its count to buffers, so every method's capture can be compared with the
// oracle's exact lists fragment by fragment (and the pixel probe can show what a method holds).
// Only pixels of the region uDumpOrigin + [0, uDumpSize) (GL window coordinates) are written.
layout(std430, binding = MFR_SSBO_DUMP) writeonly buffer DumpFragments { uvec2 dumpFragments[]; };
layout(std430, binding = MFR_SSBO_DUMP_COUNT) writeonly buffer DumpCounts { uint dumpCounts[]; };
uniform uint uDumpMax;  // fragments kept per pixel
uniform ivec2 uDumpOrigin;
uniform ivec2 uDumpSize;

struct OpState {
  bool inside;
  uint pixel;  // index in the region, row-major from its bottom row
};

void opBegin(inout OpState s, ivec2 pixel) {
  const ivec2 local = pixel - uDumpOrigin;
  s.inside = all(greaterThanEqual(local, ivec2(0))) && all(lessThan(local, uDumpSize));
  s.pixel = s.inside ? uint(local.y) * uint(uDumpSize.x) + uint(local.x) : 0u;
}

void opFragment(inout OpState s, MfrFragment f, uint position) {
  if (s.inside && position < uDumpMax) dumpFragments[s.pixel * uDumpMax + position] = mfrPack(f);
}

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) {
  if (s.inside) dumpCounts[s.pixel] = count;
  return vec4(0.0);
}
