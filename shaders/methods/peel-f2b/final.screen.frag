// Front-to-back depth peeling: Everitt, "Interactive Order-Independent Transparency", NVIDIA
// technical report, 2001. Final pass: the accumulated (C, T) plus T·background, the same last step
// as the oracle's compositeOver, written into the caller's framebuffer.
#include "common/bindings.h"

layout(binding = MFR_TEX_AUX1) uniform sampler2D uAccum;
uniform vec3 uBackground;

layout(location = 0) out vec4 outColor;

void main() {
  vec4 a = texelFetch(uAccum, ivec2(gl_FragCoord.xy), 0);
  outColor = vec4(vec3(a) + a.a * uBackground, 1.0);
}
