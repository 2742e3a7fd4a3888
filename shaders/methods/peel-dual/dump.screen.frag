// Dual depth peeling: Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA technical report, 2008. Dump pass (tests, diagnostics): peeling keeps no lists, so the
// operation (ops/dump.glsl, MFR_OP_FILE) receives each pass's layers as they are peeled: front
// layer i at position i, back layer i at position P−1−i, where P = min(n, 2·max_passes) is the
// number of fragments the peeling holds and n the pixel's fragment count from the init pass. A
// first run with uWriteCounts = 1 writes P for every pixel. With depth ties n counts fragments
// that peeling merges, so such pixels get holes (the oracle flags them).
#include "methods/peel-dual/layers.glsl"
#include MFR_OP_FILE

layout(binding = MFR_TEX_AUX0) uniform sampler2D uRange;
layout(binding = MFR_TEX_AUX1) uniform sampler2D uLayers;
layout(binding = MFR_TEX_AUX2) uniform sampler2D uCount;
uniform uint uPass;
uniform uint uMaxLayers;  // 2·max_passes
uniform int uWriteCounts;

layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  uint held = min(uint(texelFetch(uCount, p, 0).x), uMaxLayers);
  OpState s;
  opBegin(s, p);
  if (uWriteCounts != 0) {
    outColor = opEnd(s, p, held);
    return;
  }
  vec2 range = texelFetch(uRange, p, 0).xy;
  if (rangeEmpty(range)) discard;
  vec4 layers = texelFetch(uLayers, p, 0);
  if (layers.x >= 0.0) opFragment(s, MfrFragment(halvesToColor(layers.xy), -range.x), uPass);
  if (-range.x < range.y && layers.z >= 0.0 && held >= uPass + 2u)
    opFragment(s, MfrFragment(halvesToColor(layers.zw), range.y), held - 1u - uPass);
  outColor = vec4(0.0);
}
