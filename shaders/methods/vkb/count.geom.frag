// Variable k-buffer using importance maps (Vasilakis, Vardis, Papaioannou, Moustakas, EG 2017
// Short Papers): count pass. n(p) and the nearest depth per pixel into the arena (N, T(0)), for
// the depth-complexity criterion and the nearest fragment's Fresnel term. Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  atomicAdd(arena[vkN(p)], 1u);
  atomicMin(arena[vkT(0u, p)], floatBitsToUint(gl_FragCoord.z));
}
