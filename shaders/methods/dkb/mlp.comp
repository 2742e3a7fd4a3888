// Deep hybrid order-independent transparency (Tsopouridis, Fudos, Vasilakis, The Visual Computer
// 2022, §4): the 12 features of each pixel (budget/features.h) and the network's prediction
// (budget/mlp.h, weights at MFR_SSBO_WEIGHTS as 16-bit floats), turned into the importance I(p) in T(0) that the
// shared allocation rule distributes the budget by. uTarget says what the network predicts:
// 0 = k(p)/n(p) (I = y·n), 1 = k(p)/F(M) (I = y).
#include "budget/arena.glsl"
#include "budget/allocation.h"
#define MFR_OUT(T) out T
#include "budget/features.h"

#include "budget/mlp_layout.h"
layout(std430, binding = MFR_SSBO_WEIGHTS) readonly buffer DkbWeights { uint mlpWords[]; };
// Input statistics as floats, weights as packed halves (MFR_MLP_PACKED_WORDS layout).
float mlpWeight(int i) {
  if (i < MFR_MLP_W1) return uintBitsToFloat(mlpWords[i]);
  int j = i - MFR_MLP_W1;
  return unpackHalf2x16(mlpWords[MFR_MLP_W1 + (j >> 1)])[j & 1];
}
#define MFR_MLP_WEIGHT(i) mlpWeight(i)
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
  float importance = uTarget == 0u ? y * float(n) : y;
  arena[vkT(0u, p)] = floatBitsToUint(mfrSanitizeImportance(importance));
}
