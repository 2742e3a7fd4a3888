// [Hybrid transparency: Maule, Comba, Torchelsen, Bastos, "Hybrid transparency", I3D 2013; the
// tail of Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §3.3 — its exactness for a tail of one colour is our allocation bound,
// budget/allocation.h.] Tail-run pass 1 of 3: the colour of each pixel's farthest fragment (the
// one whose depth equals the feature passes' maximum in T(uVkFarRegion); equal depths keep the
// largest packed RGBA) into T(3). Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

uniform uint uVkFarRegion;

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  if (floatBitsToUint(gl_FragCoord.z) != arena[vkT(uVkFarRegion, p)]) return;
  atomicMax(arena[vkT(3u, p)], mfrCurrentFragment().color);
}
