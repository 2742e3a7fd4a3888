// S-buffer (Vasilakis & Fudos, EG 2012 short papers): store pass. Each fragment takes the next
// position of its pixel's range, offsets[p] + atomicAdd(cursor[p], 1). A fragment is dropped (and
// counted) when its position falls past the fragment buffer (a capacity from the previous frame
// or a fixed budget) or past its pixel's counted range (a store pass that rasterised more than
// the count pass): nothing is ever written out of bounds or into a neighbour's range.
// Colour writes are off (side effects only).
#include "common/fragment.glsl"
#include "methods/abuffer-sbuffer/sbuffer.glsl"

layout(std430, binding = MFR_SSBO_COUNTER) buffer SCounter {
  uint dropped;         // fragments lost
  uint overflowPixels;  // pixels that lost at least one
};

void main() {
  uint p = pixelIndex(ivec2(gl_FragCoord.xy));
  uint begin = sOffsets[p];
  uint end = min(sOffsets[p + 1u], uCapacity);
  uint limit = end > begin ? end - begin : 0u;  // positions this pixel may fill
  uint slot = atomicAdd(sCounts[p], 1u);
  if (slot >= limit) {
    atomicAdd(dropped, 1u);
    if (slot == limit) atomicAdd(overflowPixels, 1u);  // the first one dropped, once per pixel
    return;
  }
  sFragments[begin + slot] = mfrPack(mfrCurrentFragment());
}
