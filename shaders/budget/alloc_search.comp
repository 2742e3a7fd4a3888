// [Allocation of k(p) under a slot budget for the variable k-buffers: Vasilakis et al., "Variable
// k-buffer using Importance Maps", EG 2017; Tsopouridis, Fudos, Vasilakis, "Deep hybrid
// order-independent transparency", The Visual Computer 2022 — our rule, budget/allocation.h.]
// One round of the λ search: S(c_j) = Σ_p k_{c_j}(p) at the 15 candidates between lo and hi.
// Importance I(p) is in T(0, p).
#include "budget/arena.glsl"

layout(local_size_x = 256) in;

shared uint sSums[15];

void main() {
  uint t = gl_LocalInvocationIndex;
  if (t < 15u) sSums[t] = 0u;
  barrier();
  uint p = VK_INVOCATION_PIXEL(256u);
  if (p < uVkPixels) {
    uint n = arena[vkN(p)];
    if (n > 0u) {
      float importance = uintBitsToFloat(arena[vkT(0u, p)]);
      uint e = vkExactK(p, n);
      uint lo = vkLo, hi = vkHi, mode = vkAllocMode;
      for (uint j = 1u; j < MFR_ALLOC_SECTIONS; ++j) {
        uint k = mfrAllocK(uintBitsToFloat(mfrAllocCandidate(lo, hi, j)), importance, n, e, mode);
        if (k != 0u) atomicAdd(sSums[j - 1u], k);
      }
    }
  }
  barrier();
  if (t < 15u && sSums[t] != 0u) atomicAdd(vkSums[t], sSums[t]);
}
