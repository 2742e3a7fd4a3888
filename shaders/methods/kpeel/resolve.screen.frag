// k-peeling (Bavoil et al., I3D 2007, multi-pass k-buffer): final pass of the "oit" operation. The
// iterations composited every fragment front to back into the pixel's accum (colour,
// transmittance); the operation's opEnd adds the background.
#define KP_ACCESS readonly
#include "methods/kpeel/peel.glsl"
#include MFR_OP_FILE

layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  KPeelPixel state = kpPixels[kpPixel(p)];
  OpState s;
  s.color = state.accum.rgb;
  s.transmittance = kpTransmittance(state);
  outColor = opEnd(s, p, state.threshold.w);
}
