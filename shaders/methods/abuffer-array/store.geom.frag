// A-buffer with fixed-size per-pixel arrays (FreePipe, Liu et al., I3D 2010; Crassin 2010): store
// pass. The per-pixel counter hands out slots by atomic increment; it keeps counting past uSlots,
// so it ends holding the true number of arrivals, from which the stats pass derives the dropped
// fragments and overflowing pixels. A fragment past the capacity is dropped: never written out of
// bounds. Colour writes are off (side effects only).
#include "common/fragment.glsl"
#include "methods/abuffer-array/array.glsl"

layout(r32ui, binding = MFR_IMAGE_COUNTS) uniform coherent uimage2D uCounts;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  uint slot = imageAtomicAdd(uCounts, p, 1u);
  if (slot >= uSlots) return;
  arrayFragments[slot * uPixels + pixelIndex(p)] = mfrPack(mfrCurrentFragment());
}
