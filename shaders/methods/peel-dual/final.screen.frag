// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Final pass: front accumulation plus its transmittance times the
// back accumulation (which already holds the background), into the caller's framebuffer.
#include "common/bindings.h"

layout(binding = MFR_TEX_AUX1) uniform sampler2D uFront;
layout(binding = MFR_TEX_AUX2) uniform sampler2D uBack;

layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 front = texelFetch(uFront, p, 0);
  vec4 back = texelFetch(uBack, p, 0);
  outColor = vec4(vec3(front) + front.a * vec3(back), 1.0);
}
