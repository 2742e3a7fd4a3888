// Moment-based OIT (Münstermann, Krumpen, Klein, Peters, Proc. ACM CGIT 1(1), 2018): first
// additive pass. Every fragment adds its absorbance a = −ln(1 − α) and a·z'^k (k = 1..2m, z' the
// warped depth) to single-precision float targets with blend ONE, ONE (the paper's 32-bit
// variant, which needs no rasterizer-ordered views):
//   0  R32F     b_0
//   1  RGBA32F  b_1 .. b_4
//   2  RG32F    b_5, b_6          (6 moments only)
#include "common/fragment.glsl"
#include "methods/mboit/moments.glsl"

layout(location = 0) out vec4 outB0;
layout(location = 1) out vec4 outB1234;
#if MFR_MBOIT_M == 3
layout(location = 2) out vec4 outB56;
#endif

void main() {
  vec4 c = unpackUnorm4x8(mfrCurrentFragment().color);
  float a = mfrAbsorbance(c.a);
  float z = mfrWarpedDepth();
  float z2 = z * z;
  outB0 = vec4(a, 0.0, 0.0, 0.0);
  outB1234 = a * vec4(z, z2, z2 * z, z2 * z2);
#if MFR_MBOIT_M == 3
  outB56 = a * vec4(z2 * z2 * z, z2 * z2 * z2, 0.0, 0.0);
#endif
}
