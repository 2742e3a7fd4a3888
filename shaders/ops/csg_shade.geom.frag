// Operation "csg", shading pass (image-space CSG; Goldfeather, Molnar, Turk, Fuchs, IEEE CG&A 9(3)
// 1989; on multifragment lists as in Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", CGF 39(2) 2020): the scene drawn once more, colour writes on, no depth test; only
// the fragment that ops/csg.glsl chose for its pixel — same object, bit-identical window depth
// (same triangle, same invariant position) — writes its shaded colour, opaque (CSG draws solids).
#include "common/fragment.glsl"

layout(std430, binding = MFR_SSBO_CSG) readonly buffer CsgVisible { uvec2 csgVisible[]; };
uniform int uCsgWidth;
layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  uvec2 v = csgVisible[uint(p.y) * uint(uCsgWidth) + uint(p.x)];
  if (v.x != uObjectId + 1u || v.y != floatBitsToUint(gl_FragCoord.z)) discard;
  outColor = vec4(vec3(mfrShadedColor()), 1.0);
}
