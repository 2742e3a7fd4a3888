// [Allocation rule of the variable k-buffers (Vasilakis et al., EG 2017; Tsopouridis et al., The
// Visual Computer 2022), budget/allocation.h.] Final k(p): k_lo(p) plus its share of the
// R = F − S(lo) remaining slots, given in pixel order (T(1, ·) holds the exclusive prefix sum of
// the growth), so Σk = F when Σn ≥ F. Also the k range over non-empty pixels.
#include "budget/arena.glsl"

layout(local_size_x = 256) in;

void main() {
  uint p = VK_INVOCATION_PIXEL(256u);
  if (p >= uVkPixels) return;
  uint before = arena[vkT(1u, p)];
  uint growth = arena[vkT(1u, p + 1u)] - before;
  uint remaining = vkBudgetSlots > vkSumLo ? vkBudgetSlots - vkSumLo : 0u;
  uint extra = remaining > before ? min(remaining - before, growth) : 0u;
  uint k = arena[vkK(p)] + extra;
  arena[vkK(p)] = k;
  if (arena[vkN(p)] > 0u) {
    atomicMin(vkKMin, k);
    atomicMax(vkKMax, k);
  }
}
