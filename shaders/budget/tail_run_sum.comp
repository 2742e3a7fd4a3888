// [Hybrid transparency: Maule, Comba, Torchelsen, Bastos, "Hybrid transparency", I3D 2013; the
// tail of Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §3.3 — budget/allocation.h.] After the tail-run passes: Σ e(p) = Σ max(1, n − m)
// into vkExactSlots, the budget from which the frame is exact and where the allocation switches
// from capping at e(p) to filling above it. Work-group reduction, one global atomic per group.
#include "budget/arena.glsl"

layout(local_size_x = 256) in;

shared uint sExact;

void main() {
  if (gl_LocalInvocationIndex == 0u) sExact = 0u;
  barrier();
  uint p = VK_INVOCATION_PIXEL(256u);
  if (p < uVkPixels) {
    uint n = arena[vkN(p)];
    if (n > 0u) atomicAdd(sExact, mfrAllocExactK(n, arena[vkK(p)]));
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u && sExact != 0u) atomicAdd(vkExactSlots, sExact);
}
