// [Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022; Vasilakis et al., "Variable k-buffer using Importance Maps", EG 2017.] Per-image
// sums of the variable-k buffers: Σ n(p), pixels with n > 0 and n > 1, and (MFR_VK_DEPTH_RANGE, dkb) the
// image's nearest and farthest depth. Work-group reduction in shared memory, one global atomic
// per group and value.
#include "budget/arena.glsl"

layout(local_size_x = 256) in;

shared uint sTotal, sNonEmpty, sMulti, sNear, sFar;

void main() {
  if (gl_LocalInvocationIndex == 0u) {
    sTotal = 0u;
    sNonEmpty = 0u;
    sMulti = 0u;
    sNear = 0x7F800000u;
    sFar = 0u;
  }
  barrier();
  uint p = VK_INVOCATION_PIXEL(256u);
  if (p < uVkPixels) {
    uint n = arena[vkN(p)];
    if (n > 0u) {
      atomicAdd(sTotal, n);
      atomicAdd(sNonEmpty, 1u);
      if (n > 1u) atomicAdd(sMulti, 1u);
#ifdef MFR_VK_DEPTH_RANGE
      atomicMin(sNear, arena[vkT(0u, p)]);
      atomicMax(sFar, arena[vkT(1u, p)]);
#endif
    }
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    if (sTotal != 0u) atomicAdd(vkTotalFragments, sTotal);
    if (sNonEmpty != 0u) atomicAdd(vkNonEmpty, sNonEmpty);
    if (sMulti != 0u) atomicAdd(vkMultiFragment, sMulti);
    atomicMin(vkImageNearBits, sNear);
    atomicMax(vkImageFarBits, sFar);
  }
}
