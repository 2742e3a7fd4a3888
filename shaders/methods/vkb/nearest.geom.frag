// Variable k-buffer using importance maps (Vasilakis, Vardis, Papaioannou, Moustakas, EG 2017
// Short Papers): the Fresnel term of each pixel's nearest fragment (the one whose depth equals the
// count pass's minimum; equal depths keep the largest term) into T(1). Colour writes are off.
#include "common/fragment.glsl"
#include "budget/arena.glsl"
#include "budget/importance.h"

void main() {
  uint p = vkPixel(ivec2(gl_FragCoord.xy));
  if (floatBitsToUint(gl_FragCoord.z) != arena[vkT(0u, p)]) return;
  float fresnel = mfrFresnelSchlick(dot(normalize(vNormal), uViewDir));
  atomicMax(arena[vkT(1u, p)], floatBitsToUint(fresnel));
}
