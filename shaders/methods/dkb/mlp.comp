// Deep hybrid order-independent transparency (Tsopouridis, Fudos, Vasilakis, The Visual Computer
// 2022, §4): the 12 features of each pixel (budget/features.h) and the network's prediction
// (budget/mlp.h; weights in the uniform block MFR_UBO_DKB_WEIGHTS as 8-bit integers with per-row scales), turned into
// the importance I(p) in T(0) that the shared allocation rule distributes the budget by. uTarget says what the network predicts:
// 0 = k(p)/n(p), 1 = k(p)/F(M) (mfrDkbImportance).
// NVIDIA: unroll every loop, so the activations h1[], h2[] (budget/mlp.h) are indexed by constants
// and live in registers, not in local memory: the pass took 9.8 ms at 1920x1080 on an H200 before,
// 3.3 ms after, the same output (docs/results.md). Other compilers ignore the pragma.
#pragma optionNV(unroll all)
#include "budget/arena.glsl"
#include "budget/allocation.h"
#define MFR_OUT(T) out T
#include "budget/features.h"

#include "budget/mlp_layout.h"
// Statistics, biases and row scales as float words, then the weights as signed bytes, four per word
// (MFR_MLP_PACKED_WORDS layout), in a uniform block: every invocation reads the same word at once.
layout(std140, binding = MFR_UBO_DKB_WEIGHTS) uniform DkbWeights { uvec4 mlpWords[MFR_MLP_PACKED_WORDS / 4]; };
#define MFR_MLP_WORD(i) mlpWords[(i) >> 2][(i) & 3]
#define MFR_MLP_STAT(i) uintBitsToFloat(MFR_MLP_WORD(i))
#define MFR_MLP_BIAS(r) uintBitsToFloat(MFR_MLP_WORD(MFR_MLP_GPU_BIAS + (r)))
#define MFR_MLP_SCALE(r) uintBitsToFloat(MFR_MLP_WORD(MFR_MLP_GPU_SCALE + (r)))
// Four signed bytes of one word (bitfieldExtract sign-extends).
vec4 mlpQuad(int q) {
  int w = int(MFR_MLP_WORD(MFR_MLP_GPU_QUANT + (q >> 2)));
  return vec4(bitfieldExtract(w, 0, 8), bitfieldExtract(w, 8, 8), bitfieldExtract(w, 16, 8), bitfieldExtract(w, 24, 8));
}
#define MFR_MLP_QUAD(q) mlpQuad(q)
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
