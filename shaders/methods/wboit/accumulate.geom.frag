// Weighted blended OIT: McGuire & Bavoil, "Weighted Blended Order-Independent Transparency",
// JCGT 2(2), 2013. Accumulation pass (the paper's single geometry pass), two render targets:
//   0  RGBA16F  += (w·α·c, w·α)   blend ONE, ONE                   (eq. 6 numerator/denominator)
//   1  R8/R16F  *= (1 − α)        blend ZERO, ONE_MINUS_SRC_COLOR  (revealage Π(1 − α))
// c is straight colour, so α·c is the paper's premultiplied C_i. The weight w(z, α) is chosen at
// compile time by MFR_WBOIT_WEIGHT: 7, 8, 9 (view depth |z|), 10 (window depth), 0 (w = 1: plain
// weighted average, for comparison). Every weight is clamped to [1e-2, 3e3] as in the paper, which
// keeps Σ w·α inside half-float range for a few dozen layers.
#include "common/fragment.glsl"
#include "methods/wboit/view_depth.glsl"

layout(location = 0) out vec4 outAccum;
layout(location = 1) out vec4 outRevealage;

float depthWeight() {
#if MFR_WBOIT_WEIGHT == 7
  float z = mfrViewDepth();
  float z5 = z / 5.0, z200 = z / 200.0;
  float z200_3 = z200 * z200 * z200;
  return clamp(10.0 / (1e-5 + z5 * z5 + z200_3 * z200_3), 1e-2, 3e3);
#elif MFR_WBOIT_WEIGHT == 8
  float z = mfrViewDepth();
  float z10 = z / 10.0, z200 = z / 200.0;
  float z200_3 = z200 * z200 * z200;
  return clamp(10.0 / (1e-5 + z10 * z10 * z10 + z200_3 * z200_3), 1e-2, 3e3);
#elif MFR_WBOIT_WEIGHT == 9
  float z200 = mfrViewDepth() / 200.0;
  float z200_2 = z200 * z200;
  return clamp(0.03 / (1e-5 + z200_2 * z200_2), 1e-2, 3e3);
#elif MFR_WBOIT_WEIGHT == 10
  float d = 1.0 - gl_FragCoord.z;
  return max(1e-2, 3e3 * d * d * d);
#else
  return 1.0;
#endif
}

void main() {
  // The 8-bit colour every method stores and the oracle composites (common/payload.glsl).
  vec4 c = unpackUnorm4x8(mfrCurrentFragment().color);
#if MFR_WBOIT_WEIGHT == 0
  float w = 1.0;
#else
  float w = c.a * depthWeight();  // the paper's w(z, α) = α · clamp(…)
#endif
  outAccum = vec4(c.rgb * c.a, c.a) * w;
  outRevealage = vec4(c.a);
}
