// View-space depth for the depth-weighted OIT methods: McGuire & Bavoil, "Weighted Blended
// Order-Independent Transparency", JCGT 2(2), 2013 (weights of eqs. 7-9 take |z_eye|), and the
// moment-based OIT of Münstermann et al. 2018 (logarithmic depth warp), which includes this file.
// The frame only carries viewProj, so C++ (DepthMapping in weighted_blended_oit.cpp) recovers the
// depth row of the projection from it:
//   perspective:  |z_eye| = b / (ndc_z + a)         (exact)
//   orthographic: d = (ndc_z + 1) / a               (distance behind the near plane: the eye's
//                 position along the view axis cancels out of P·V, so |z_eye| itself is unknown)
#ifndef MFR_VIEW_DEPTH_GLSL
#define MFR_VIEW_DEPTH_GLSL
uniform int uPerspective;  // 1: perspective projection, 0: orthographic
uniform vec2 uDepthMap;    // (a, b) above

float mfrViewDepth() {
  float ndc = 2.0 * gl_FragCoord.z - 1.0;  // default depth range [0, 1], clip control -1..1
  return uPerspective != 0 ? uDepthMap.y / (ndc + uDepthMap.x) : (ndc + 1.0) / uDepthMap.x;
}
#endif
