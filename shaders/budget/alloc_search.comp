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
  // Each invocation sums MFR_ALLOC_SEARCH_PIXELS pixels (strided by the group size, so a group
  // still reads neighbouring words) before one shared atomic per candidate: the atomics, not the
  // rule, were the pass's cost.
  uint sums[15];
  for (uint j = 0u; j < 15u; ++j) sums[j] = 0u;
  uint first = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * (256u * MFR_ALLOC_SEARCH_PIXELS) + t;
  uint lo = vkLo, hi = vkHi, mode = vkAllocMode;
  for (uint i = 0u; i < MFR_ALLOC_SEARCH_PIXELS; ++i) {
    uint p = first + i * 256u;
    if (p >= uVkPixels) break;
    uint n = arena[vkN(p)];
    if (n == 0u) continue;
    float importance = uintBitsToFloat(arena[vkT(0u, p)]);
    uint e = vkExactK(p, n);
    for (uint j = 1u; j < MFR_ALLOC_SECTIONS; ++j)
      sums[j - 1u] += mfrAllocK(uintBitsToFloat(mfrAllocCandidate(lo, hi, j)), importance, n, e, mode);
  }
  for (uint j = 0u; j < 15u; ++j)
    if (sums[j] != 0u) atomicAdd(sSums[j], sums[j]);
  barrier();
  if (t < 15u && sSums[t] != 0u) atomicAdd(vkSums[t], sSums[t]);
}
