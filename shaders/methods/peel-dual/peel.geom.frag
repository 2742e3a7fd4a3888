// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Geometry pass, MAX blending on every colour target.
// uInit = 1, the paper's initialisation pass: every fragment writes (−z, z), giving the range of
// the first pass, and 1 into target 1 (ADD-blended there: the per-pixel count, used by the dump).
// Peel pass: fragments outside the range were peeled earlier (discarded); those strictly inside
// form the next range; those at exactly the nearest / farthest depth are this pass's front / back
// layer. A range with nearest == farthest (odd layer count) peels its fragment once, as front.
// Fragments of equal depth reach the same target together (componentwise MAX): depth ties are the
// method's known limitation. Init and peel share this program so both see the same gl_FragCoord.z.
#include "common/fragment.glsl"
#include "methods/peel-dual/layers.glsl"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uRange;  // range this pass peels
uniform int uInit;

layout(location = 0) out vec2 outRange;
layout(location = 1) out vec4 outLayers;

void main() {
  float z = gl_FragCoord.z;
  if (uInit != 0) {
    outRange = vec2(-z, z);
    outLayers = vec4(1.0);
    return;
  }
  vec2 range = texelFetch(uRange, ivec2(gl_FragCoord.xy), 0).xy;
  float nearest = -range.x, farthest = range.y;
  if (z < nearest || z > farthest) discard;  // peeled earlier, or nothing left (empty range)
  outRange = vec2(PEEL_EMPTY);  // neutral under MAX
  outLayers = vec4(-1.0);
  if (z > nearest && z < farthest) {
    outRange = vec2(-z, z);
    return;
  }
  vec2 c = colorToHalves(mfrCurrentFragment().color);
  if (z == nearest) outLayers.xy = c;
  else outLayers.zw = c;
}
