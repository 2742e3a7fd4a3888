// Moment-based OIT (Münstermann, Krumpen, Klein, Peters, Proc. ACM CGIT 1(1), 2018): second
// additive pass. Each fragment reconstructs the transmittance T in front of its own depth from
// its pixel's moments and adds (T·α·c, T·α) to an RGBA16F target with blend ONE, ONE.
#include "common/fragment.glsl"
#include "methods/mboit/moments.glsl"
#include "methods/mboit/transmittance.glsl"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uB0;
layout(binding = MFR_TEX_AUX1) uniform sampler2D uB1234;
#if MFR_MBOIT_M == 3
layout(binding = MFR_TEX_AUX2) uniform sampler2D uB56;
#endif

layout(location = 0) out vec4 outAccum;

void main() {
  vec4 c = unpackUnorm4x8(mfrCurrentFragment().color);
  ivec2 p = ivec2(gl_FragCoord.xy);
  float b0 = texelFetch(uB0, p, 0).r;
  vec4 b1234 = texelFetch(uB1234, p, 0);
#if MFR_MBOIT_M == 2
  float raw[4] = float[4](b1234.x, b1234.y, b1234.z, b1234.w);
#else
  vec2 b56 = texelFetch(uB56, p, 0).rg;
  float raw[6] = float[6](b1234.x, b1234.y, b1234.z, b1234.w, b56.x, b56.y);
#endif
  float t = mfrTransmittanceAt(b0, raw, mfrWarpedDepth());
  outAccum = vec4(c.rgb * c.a, c.a) * t;
}
