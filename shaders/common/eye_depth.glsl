// [Z-thickness blending — Kim & Kye, "Z-Thickness Blending: Effective Fragment Merging for
// Multi-Fragment Rendering", Computer Graphics Forum 40(7) 2021.] Window depth → eye depth (distance
// along the view axis), for thicknesses in scene units: z = -(a·ndc + b)/(c·ndc + d), ndc = 2·depth - 1,
// with (a, b, c, d) = Camera::depthToEye() (the inverse projection's z row).
#ifndef MFR_EYE_DEPTH_GLSL
#define MFR_EYE_DEPTH_GLSL
uniform vec4 uDepthToEye;

float mfrEyeDepth(float windowDepth) {
  float ndc = 2.0 * windowDepth - 1.0;
  return -(uDepthToEye.x * ndc + uDepthToEye.y) / (uDepthToEye.z * ndc + uDepthToEye.w);
}
#endif
