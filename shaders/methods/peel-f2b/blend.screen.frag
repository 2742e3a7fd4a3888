// Front-to-back depth peeling: Everitt, "Interactive Order-Independent Transparency", NVIDIA
// technical report, 2001. Blend pass: composites the layer just peeled under the accumulated
// image with fixed-function blending (C += T·α·c, T *= 1−α; factors DST_ALPHA, ONE / ZERO,
// ONE_MINUS_SRC_ALPHA on an RGBA32F target holding (C, T), as in Bavoil & Myers 2008).
// Pixels without a layer are discarded, so the pass's occlusion query counts the peeled fragments
// and stops the peeling at zero. With colour writes off it only counts (overflow check).
#include "methods/peel-f2b/layer.glsl"

layout(binding = MFR_TEX_AUX1) uniform usampler2D uLayer;

layout(location = 0) out vec4 outColor;

void main() {
  uvec2 layer = texelFetch(uLayer, ivec2(gl_FragCoord.xy), 0).xy;
  if (!peelPresent(layer)) discard;
  vec4 c = unpackUnorm4x8(layer.x);
  outColor = vec4(c.a * vec3(c), c.a);
}
