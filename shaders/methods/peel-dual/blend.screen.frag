// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Blend pass after each peel: the front layer goes under the front
// accumulation (C += T·α·c, T *= 1−α: factors DST_ALPHA, ONE / ZERO, ONE_MINUS_SRC_ALPHA), the back
// layer over the back accumulation, which starts as the background (α·c + (1−α)·B: ONE,
// ONE_MINUS_SRC_ALPHA). The paper blends the front inside the peel pass through a ping-pong
// texture; a separate full-screen pass needs one RGBA32F target less and keeps the peel pass free
// of colour arithmetic.
#include "methods/peel-dual/layers.glsl"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uRange;
layout(binding = MFR_TEX_AUX1) uniform sampler2D uLayers;

layout(location = 0) out vec4 outFront;
layout(location = 1) out vec4 outBack;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec2 range = texelFetch(uRange, p, 0).xy;
  if (rangeEmpty(range)) discard;
  vec4 layers = texelFetch(uLayers, p, 0);
  outFront = vec4(0.0);  // neutral for both blends
  outBack = vec4(0.0);
  if (layers.x >= 0.0) {
    vec4 c = unpackUnorm4x8(halvesToColor(layers.xy));
    outFront = vec4(c.a * vec3(c), c.a);
  }
  if (-range.x < range.y && layers.z >= 0.0) {
    vec4 c = unpackUnorm4x8(halvesToColor(layers.zw));
    outBack = vec4(c.a * vec3(c), c.a);
  }
}
