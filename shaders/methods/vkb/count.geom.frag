// Variable k-buffer using importance maps (Vasilakis, Vardis, Papaioannou, Moustakas, EG 2017
// Short Papers): count pass. n(p) and the nearest depth per pixel into the arena (N, T(0)), for
// the depth-complexity criterion and the nearest fragment's Fresnel term, and the farthest depth
// (T(2)) for the tail-run passes. Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  atomicAdd(arena[vkN(p)], 1u);
  uint depth = floatBitsToUint(gl_FragCoord.z);
  atomicMin(arena[vkT(0u, p)], depth);
  atomicMax(arena[vkT(2u, p)], depth);
}
