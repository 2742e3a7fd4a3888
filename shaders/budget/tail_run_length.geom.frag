// [Hybrid transparency: Maule, Comba, Torchelsen, Bastos, "Hybrid transparency", I3D 2013; the
// tail of Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §3.3 — budget/allocation.h.] Tail-run pass 3 of 3: m(p), the fragments strictly
// behind every fragment of another colour (all of them, when there is none), counted into K(p)
// for the allocation (MFR_ALLOC_RUNS). Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  if (floatBitsToUint(gl_FragCoord.z) + 1u > arena[vkT(4u, p)]) atomicAdd(arena[vkK(p)], 1u);
}
