// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Counting pass; the occlusion query around it counts pixels:
// uTwoLayers = 0, the stop test: pixels whose range is non-empty, i.e. that still hold unpeeled
// fragments. Counting blended layers instead would miss layers of alpha 0, and a query on the next
// peel pass would cost one empty geometry pass at the end.
// uTwoLayers = 1: pixels whose range has two distinct ends, i.e. where the pass peeling it
// composites a front and a back layer (one where nearest == farthest). Summed over the passes with
// the stop counts, these give the layers composited, so fragments lost to depth ties are counted.
#include "methods/peel-dual/layers.glsl"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uRange;
uniform int uTwoLayers;

layout(location = 0) out vec4 outColor;

void main() {
  vec2 range = texelFetch(uRange, ivec2(gl_FragCoord.xy), 0).xy;
  if (rangeEmpty(range) || (uTwoLayers != 0 && !(-range.x < range.y))) discard;
  outColor = vec4(0.0);
}
