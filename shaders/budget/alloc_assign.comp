// [Allocation rule of the variable k-buffers (Vasilakis et al., EG 2017; Tsopouridis et al., The
// Visual Computer 2022), budget/allocation.h.] After the search: k_lo(p) = k at λ_lo into K(p),
// and how much k grows up to λ_hi into T(1, p), whose prefix sum decides which pixels take the
// F − S(lo) remaining slots. Element W·H of both is 0 (the scans run over W·H + 1 elements).
#include "budget/arena.glsl"

layout(local_size_x = 256) in;

void main() {
  uint p = VK_INVOCATION_PIXEL(256u);
  if (p >= uVkPixels) return;
  uint n = arena[vkN(p)];
  float importance = uintBitsToFloat(arena[vkT(0u, p)]);
  uint e = vkExactK(p, n);
  uint kLo = mfrAllocK(uintBitsToFloat(vkLo), importance, n, e, vkAllocMode);
  uint kHi = mfrAllocK(uintBitsToFloat(vkHi), importance, n, e, vkAllocMode);
  arena[vkK(p)] = kLo;
  arena[vkT(1u, p)] = kHi - kLo;
  if (p == 0u) {
    arena[vkK(uVkPixels)] = 0u;
    arena[vkT(1u, uVkPixels)] = 0u;
  }
}
