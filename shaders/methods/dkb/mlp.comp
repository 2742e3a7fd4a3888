// Deep hybrid order-independent transparency (Tsopouridis, Fudos, Vasilakis, The Visual Computer
// 2022, §4): the 12 features of each pixel (budget/features.h) and the network's prediction
// (budget/mlp.h; weights at MFR_SSBO_WEIGHTS as 8-bit integers with per-row scales), turned into
// the importance I(p) in T(0) that the shared allocation rule distributes the budget by. uTarget says what the network predicts:
// 0 = k(p)/n(p), 1 = k(p)/F(M) (mfrDkbImportance).
#include "budget/arena.glsl"
#include "budget/allocation.h"
#define MFR_OUT(T) out T
#include "budget/features.h"

#include "budget/mlp_layout.h"
layout(std430, binding = MFR_SSBO_WEIGHTS) readonly buffer DkbWeights { uint mlpWords[]; };
// Statistics, biases and row scales as floats; weights as signed bytes (MFR_MLP_PACKED_WORDS layout).
#define MFR_MLP_STAT(i) uintBitsToFloat(mlpWords[i])
#define MFR_MLP_BIAS(f, b) uintBitsToFloat(mlpWords[MFR_MLP_GPU_BIAS + (b)])
float mlpRowWeight(int q, int row) {
  int byte = bitfieldExtract(int(mlpWords[MFR_MLP_GPU_QUANT + (q >> 2)]), 8 * (q & 3), 8);  // sign-extends
  return uintBitsToFloat(mlpWords[MFR_MLP_GPU_SCALE + row]) * float(byte);
}
#define MFR_MLP_ROW_WEIGHT(f, q, r) mlpRowWeight(q, r)
#include "budget/mlp.h"

layout(local_size_x = 64) in;

uniform uint uTarget;

void main() {
  uint p = VK_INVOCATION_PIXEL(64u);
  if (p >= uVkPixels) return;
  uint n = arena[vkN(p)];
  if (n == 0u) {
    arena[vkT(0u, p)] = 0u;
    return;
  }
  vec3 colorSum = vec3(float(arena[vkT(2u, p)]), float(arena[vkT(3u, p)]), float(arena[vkT(4u, p)]));
  vec4 a, b, c;
  mfrDkbFeatures(n, float(vkTotalFragments), float(vkBudgetSlots), uintBitsToFloat(arena[vkT(0u, p)]),
                 uintBitsToFloat(arena[vkT(1u, p)]), uintBitsToFloat(vkImageNearBits),
                 uintBitsToFloat(vkImageFarBits), arena[vkK(p)], colorSum, a, b, c);
  float y = mfrMlpForward(a, b, c);
  arena[vkT(0u, p)] = floatBitsToUint(mfrSanitizeImportance(mfrDkbImportance(y, n, uTarget == 0u)));
}
