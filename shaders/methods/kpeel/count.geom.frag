// k-peeling (Bavoil et al., I3D 2007, multi-pass k-buffer): count pass. n(p) per pixel and its
// maximum give the number of peeling iterations, ceil(max n(p) / k), before any of them runs.
#include "common/fragment.glsl"
#include "methods/kpeel/peel.glsl"

layout(r32ui, binding = MFR_IMAGE_COUNTS) uniform coherent uimage2D uCounts;

void main() {
  uint before = imageAtomicAdd(uCounts, ivec2(gl_FragCoord.xy), 1u);
  atomicMax(kpMaxCount, before + 1u);
  atomicAdd(kpGenerated, 1u);
}
