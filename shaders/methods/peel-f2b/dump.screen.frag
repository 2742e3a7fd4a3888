// Front-to-back depth peeling: Everitt, "Interactive Order-Independent Transparency", NVIDIA
// technical report, 2001. Dump pass (tests, diagnostics): peeling keeps no lists, so the operation
// (ops/dump.glsl, MFR_OP_FILE) receives each layer as it is peeled: layer i is the pixel's i-th
// nearest fragment, written at position i, with the count so far. A first run with
// uWriteCounts = 1 gives every pixel the count 0 (pixels without fragments are never peeled).
#include "methods/peel-f2b/layer.glsl"
#include MFR_OP_FILE

layout(binding = MFR_TEX_AUX1) uniform usampler2D uLayer;
uniform uint uLayerIndex;
uniform int uWriteCounts;

layout(location = 0) out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  OpState s;
  opBegin(s, p);
  if (uWriteCounts != 0) {
    outColor = opEnd(s, p, 0u);
    return;
  }
  uvec2 layer = texelFetch(uLayer, p, 0).xy;
  if (!peelPresent(layer)) discard;  // before any write: the occlusion query counts layer pixels
  opFragment(s, mfrUnpack(layer), uLayerIndex);
  outColor = opEnd(s, p, uLayerIndex + 1u);
}
