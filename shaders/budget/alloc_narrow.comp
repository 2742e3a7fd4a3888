// [Allocation rule of the variable k-buffers (Vasilakis et al., EG 2017; Tsopouridis et al., The
// Visual Computer 2022), budget/allocation.h.] Ends a λ search round on one invocation: the new
// interval is [c_j, c_{j+1}] with c_j the largest candidate whose S fits the budget F; the sums
// are cleared for the next round.
#include "budget/arena.glsl"
#include "budget/allocation.h"

layout(local_size_x = 1) in;

void main() {
  uint lo = vkLo, hi = vkHi;
  uint newLo = lo, newHi = hi, newSum = vkSumLo;
  bool over = false;
  for (uint j = 1u; j < MFR_ALLOC_SECTIONS; ++j) {
    uint c = mfrAllocCandidate(lo, hi, j);
    if (!over) {
      if (vkSums[j - 1u] <= vkBudgetSlots) {
        newLo = c;
        newSum = vkSums[j - 1u];
      } else {
        newHi = c;
        over = true;
      }
    }
    vkSums[j - 1u] = 0u;
  }
  vkLo = newLo;
  vkHi = newHi;
  vkSumLo = newSum;
}
