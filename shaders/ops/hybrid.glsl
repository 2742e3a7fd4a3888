// Operation "hybrid": hybrid transparency as in Tsopouridis, Fudos, Vasilakis, "Deep hybrid
// order-independent transparency", The Visual Computer 2022, §3.3 (after Maule, Comba,
// Torchelsen, Bastos, "Hybrid transparency", I3D 2013). The core (the k nearest fragments the
// method kept, sorted by the resolve driver) is composited with "over"; the tail (every fragment
// beyond them) is replaced by its α-weighted average colour with transmittance (1 − α_avg)^t:
//   C = C_core + τ_core·(C_tail + τ_tail·C_bg), C_tail = (Σcα/Σα)·(1 − τ_tail).
// The tail comes from the k-buffer family's tail hook (--param tail=true): five exact integer
// sums per pixel at MFR_SSBO_TAIL (common/kbuffer_array.glsl), indexed with its kbPixel(). Same
// arithmetic, in the same order, as the oracle's compositeHybrid (mfrcore/src/reference/hybrid.cpp).
#ifndef MFR_KBUFFER_ARRAY_GLSL
#error "ops/hybrid.glsl needs a k-buffer family resolve pass (common/kbuffer_resolve.glsl)"
#endif

layout(std430, binding = MFR_SSBO_TAIL) readonly buffer HybridTailSums { uint hybridTail[]; };

// The core: "over", shared with the oit operation.
#include "ops/over_core.glsl"

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) {
  uint base = 5u * kbPixel(pixel);
  uint alphaSum = hybridTail[base + 3u];
  uint tailCount = hybridTail[base + 4u];
  vec3 tailColor = vec3(0.0);
  float tailAlpha = 0.0;
  if (tailCount > 0u && alphaSum > 0u) {  // empty or fully transparent tail: background only
    float alphaAvg = (float(alphaSum) / 255.0) / float(tailCount);
    tailAlpha = 1.0 - pow(max(1.0 - alphaAvg, 0.0), float(tailCount));
    vec3 colorAlpha = vec3(float(hybridTail[base]), float(hybridTail[base + 1u]), float(hybridTail[base + 2u]));
    tailColor = colorAlpha / (255.0 * float(alphaSum)) * tailAlpha;
  }
  return vec4(s.color + s.transmittance * (tailColor + (1.0 - tailAlpha) * uBackground), 1.0);
}
