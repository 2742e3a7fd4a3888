// [Hybrid transparency: Maule, Comba, Torchelsen, Bastos, "Hybrid transparency", I3D 2013; the
// tail of Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §3.3 — budget/allocation.h.] Tail-run pass 2 of 3: where the final run of the
// farthest colour breaks — the largest depth of a fragment of another colour, as float bits + 1
// (0: every fragment has the farthest colour) into T(4). Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  if (mfrCurrentFragment().color == arena[vkT(3u, p)]) return;
  atomicMax(arena[vkT(4u, p)], floatBitsToUint(gl_FragCoord.z) + 1u);
}
