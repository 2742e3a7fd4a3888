// Variable k-buffer using importance maps (Vasilakis, Vardis, Papaioannou, Moustakas, EG 2017
// Short Papers): the importance map I(p) from periphery, depth complexity, Fresnel and noise
// (budget/importance.h), into T(0) for the allocation passes.
#include "budget/arena.glsl"
#include "budget/allocation.h"
#include "budget/importance.h"

layout(local_size_x = 256) in;

uniform vec2 uImageSize;
uniform vec2 uPointOfInterest;  // in [0, 1]², y down like image rows
uniform float uFalloff;
uniform float uDepthLimit;
uniform float uDepthAlpha;
uniform vec3 uWeights;  // periphery, depth, Fresnel
uniform float uNoise;

void main() {
  uint p = VK_INVOCATION_PIXEL(256u);
  if (p >= uVkPixels) return;
  uint n = arena[vkN(p)];
  if (n == 0u) {
    arena[vkT(0u, p)] = 0u;
    return;
  }
  uint x = p % uint(uVkWidth), yGl = p / uint(uVkWidth);
  float yImage = uImageSize.y - 1.0 - float(yGl);  // image rows top-down
  float periphery = mfrPeriphery(vec2(float(x) + 0.5, yImage + 0.5), uImageSize, uPointOfInterest, uFalloff);
  float depth = mfrDepthImportance(n, uDepthLimit, uDepthAlpha);
  float fresnel = uintBitsToFloat(arena[vkT(1u, p)]);
  float noise = mfrPixelNoise(x, uint(yImage));
  float importance = mfrCombineImportance(periphery, depth, fresnel, uWeights, uNoise, noise);
  arena[vkT(0u, p)] = floatBitsToUint(mfrSanitizeImportance(importance));
}
