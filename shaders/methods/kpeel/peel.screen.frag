// k-peeling (Bavoil et al., I3D 2007, multi-pass k-buffer): per-iteration screen pass. Gathers the
// pixel's (at most k) captured entries, empties the slots for the next iteration, sorts them by
// key and hands them to the operation front to back, then moves the pixel's threshold to the
// largest key it composited.
//   MFR_KPEEL_CARRY: the "oit" operation; its state (colour, transmittance: the fields of
//     ops/oit.glsl's OpState) is carried between iterations in the pixel's accum, so compositing
//     continues front to back across iterations; the final resolve pass adds the background.
//   otherwise (stateless per-fragment operations, e.g. "dump"): opBegin/opFragment/opEnd run in
//     every iteration with positions continuing from the fragments composited before.
// Colour writes are off during these passes.
#include "methods/kpeel/peel.glsl"
#include MFR_OP_FILE

layout(location = 0) out vec4 outColor;
uniform uint uIteration;

uvec4 gLocal[KP_LOCAL];

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  uint pixel = kpPixel(p);
  uint m = 0u;
  for (uint i = 0u; i < uKbK; ++i) {
    uint slot = kpSlot(pixel, i);
    uvec4 e = kpEntries[slot];
    if (e.y == KP_EMPTY) continue;
    kpEntries[slot] = uvec4(0u, KP_EMPTY, 0u, 0u);
    // Insertion sort by key (k is small; the entries arrive in max-array order).
    int j = int(m) - 1;
    while (j >= 0 && kpLess(kpKey(e), kpKey(gLocal[j]))) {
      gLocal[j + 1] = gLocal[j];
      --j;
    }
    gLocal[j + 1] = e;
    ++m;
  }
  KPeelPixel state = kpPixels[pixel];
  uint emitted = state.threshold.w;
  outColor = vec4(0.0);
#ifdef MFR_KPEEL_CARRY
  OpState s;
  s.color = state.accum.rgb;
  s.transmittance = kpTransmittance(state);
  for (uint i = 0u; i < m; ++i) opFragment(s, MfrFragment(gLocal[i].x, uintBitsToFloat(gLocal[i].y)), emitted + i);
  state.accum = vec4(s.color, s.transmittance);
#else
  if (m > 0u || uIteration == 0u) {
    OpState s;
    opBegin(s, p);
    for (uint i = 0u; i < m; ++i) opFragment(s, MfrFragment(gLocal[i].x, uintBitsToFloat(gLocal[i].y)), emitted + i);
    outColor = opEnd(s, p, emitted + m);
  }
#endif
  if (m > 0u) {
    state.threshold = uvec4(kpKey(gLocal[m - 1u]), emitted + m);
    atomicAdd(kpCaptured, m);
  }
  kpPixels[pixel] = state;
}
