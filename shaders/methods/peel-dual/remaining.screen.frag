// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Stop test: the occlusion query around this pass counts the pixels
// whose next range is non-empty, i.e. that still hold unpeeled fragments. Counting blended layers
// instead would miss layers of alpha 0, and a query on the next peel pass would cost one empty
// geometry pass at the end.
#include "methods/peel-dual/layers.glsl"

layout(binding = MFR_TEX_AUX0) uniform sampler2D uRange;

layout(location = 0) out vec4 outColor;

void main() {
  if (rangeEmpty(texelFetch(uRange, ivec2(gl_FragCoord.xy), 0).xy)) discard;
  outColor = vec4(0.0);
}
