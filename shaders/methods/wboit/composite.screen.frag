// Weighted blended OIT: McGuire & Bavoil, "Weighted Blended Order-Independent Transparency",
// JCGT 2(2), 2013. Composite pass, eq. 6 over the background C_0:
//   C = (Σ w·α·c / Σ w·α) · (1 − Π(1 − α)) + C_0 · Π(1 − α)
// The paper blends (average, revealage) over the opaque image with ONE_MINUS_SRC_ALPHA, SRC_ALPHA;
// with a constant background this is the same sum, written directly.
#include "common/bindings.h"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uAccum;
layout(binding = MFR_TEX_AUX1) uniform sampler2D uRevealage;
uniform vec3 uBackground;

layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  // A half-float sum that overflowed (too many layers of weight 3e3) would give inf/inf; clamping
  // both to the largest half keeps the average finite.
  vec4 accum = min(texelFetch(uAccum, p, 0), vec4(65504.0));
  float revealage = texelFetch(uRevealage, p, 0).r;
  vec3 average = accum.rgb / max(accum.a, 1e-5);
  outColor = vec4(average * (1.0 - revealage) + uBackground * revealage, 1.0);
}
