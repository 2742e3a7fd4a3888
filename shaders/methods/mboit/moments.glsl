// Moment-based OIT: Münstermann, Krumpen, Klein, Peters, "Moment-Based Order-Independent
// Transparency", Proc. ACM CGIT 1(1), 2018 (i3D 2018). Shared by both geometry passes: the warped
// depth and the fragment's absorbance.
// MFR_MBOIT_M = m: 2m power moments b_1..b_2m of the absorbance distribution over warped depth,
// plus b_0 = total absorbance (m = 2: 4 moments, m = 3: 6 moments).
#ifndef MFR_MBOIT_MOMENTS_GLSL
#define MFR_MBOIT_MOMENTS_GLSL
#include "methods/wboit/view_depth.glsl"

// Depth warp to [-1, 1]. The paper warps logarithmically, z' = ln|z| between ln(near) and ln(far):
// it spends moment precision evenly over relative depth. uWarp = (offset, scale) is computed in
// C++ (MomentBasedOit) for the logarithmic or linear mapping of mfrViewDepth().
uniform int uWarpLog;
uniform vec2 uWarp;

float mfrWarpedDepth() {
  float d = mfrViewDepth();
  float x = uWarpLog != 0 ? log(max(d, 1e-30)) : d;
  return clamp(2.0 * (x - uWarp.x) * uWarp.y - 1.0, -1.0, 1.0);
}

// Absorbance −ln(1 − α), capped: α = 1 would be infinite (the cap is transmittance e^-10).
const float MFR_MBOIT_MAX_ABSORBANCE = 10.0;
float mfrAbsorbance(float alpha) { return min(-log(max(1.0 - alpha, 1e-30)), MFR_MBOIT_MAX_ABSORBANCE); }
#endif
