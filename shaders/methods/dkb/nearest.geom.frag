// Deep hybrid order-independent transparency (Tsopouridis, Fudos, Vasilakis, The Visual Computer
// 2022), feature pass 2: the colour of each pixel's nearest fragment (depth equal to pass 1's
// minimum; equal depths keep the largest packed value, so the result is deterministic) into K(p).
// Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  if (floatBitsToUint(gl_FragCoord.z) != arena[vkT(0u, p)]) return;
  atomicMax(arena[vkK(p)], mfrCurrentFragment().color);
}
