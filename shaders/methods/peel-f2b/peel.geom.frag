// Front-to-back depth peeling: Everitt, "Interactive Order-Independent Transparency", NVIDIA
// technical report, 2001. Peel pass: keeps only fragments strictly behind the previous layer
// (that layer's exact depth bits, read from its payload texture); the depth test (GL_LESS into a
// DEPTH_COMPONENT32F attachment) then selects the nearest of them, whose payload this pass writes.
// gl_FragDepth = gl_FragCoord.z makes the depth test compare the same float the next pass reads
// back. Fragments at exactly the previous depth (coplanar ties) are never peeled: the method's
// known limitation. The overflow check runs this shader with the depth test off, only counting.
#include "common/fragment.glsl"
#include "methods/peel-f2b/layer.glsl"

layout(binding = MFR_TEX_AUX0) uniform usampler2D uPrevious;  // previous layer (depth -1 before the first)

layout(location = 0) out uvec2 outLayer;

void main() {
  uvec2 previous = texelFetch(uPrevious, ivec2(gl_FragCoord.xy), 0).xy;
  // A pixel whose previous pass found nothing is finished; otherwise peel strictly behind.
  if (!peelPresent(previous) || !(gl_FragCoord.z > uintBitsToFloat(previous.y))) discard;
  gl_FragDepth = gl_FragCoord.z;
  outLayer = mfrPack(mfrCurrentFragment());
}
