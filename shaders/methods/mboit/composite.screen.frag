// Moment-based OIT (Münstermann, Krumpen, Klein, Peters, Proc. ACM CGIT 1(1), 2018): composite.
// The accumulated colour is normalised by its accumulated opacity and given the exact total
// opacity 1 − exp(−b_0), which the moments know without approximation:
//   C = (Σ T·α·c / Σ T·α) · (1 − e^{−b_0}) + C_0 · e^{−b_0}
#include "common/bindings.h"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uB0;
layout(binding = MFR_TEX_AUX1) uniform sampler2D uAccum;
uniform vec3 uBackground;

layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float transmittance = exp(-texelFetch(uB0, p, 0).r);
  vec4 accum = min(texelFetch(uAccum, p, 0), vec4(65504.0));
  vec3 average = accum.rgb / max(accum.a, 1e-5);
  outColor = vec4(average * (1.0 - transmittance) + uBackground * transmittance, 1.0);
}
