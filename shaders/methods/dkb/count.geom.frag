// Deep hybrid order-independent transparency (Tsopouridis, Fudos, Vasilakis, The Visual Computer
// 2022), feature pass 1: per pixel n(p), nearest and farthest depth, and the colour sums of all
// fragments (mean colour) into the arena (N, T(0..4)). Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  uint depth = floatBitsToUint(gl_FragCoord.z);
  uint color = mfrCurrentFragment().color;
  atomicAdd(arena[vkN(p)], 1u);
  atomicMin(arena[vkT(0u, p)], depth);
  atomicMax(arena[vkT(1u, p)], depth);
  atomicAdd(arena[vkT(2u, p)], color & 255u);
  atomicAdd(arena[vkT(3u, p)], (color >> 8u) & 255u);
  atomicAdd(arena[vkT(4u, p)], (color >> 16u) & 255u);
}
