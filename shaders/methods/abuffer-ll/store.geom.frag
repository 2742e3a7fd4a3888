// A-buffer with per-pixel linked lists (Yang et al., EGSR 2010): store pass. Each fragment takes
// a node from the global pool with an atomic counter and pushes it onto its pixel's list with an
// atomic exchange of the head pointer. Colour writes are off (side effects only).
#include "common/fragment.glsl"
#include "methods/abuffer-ll/nodes.glsl"

layout(r32ui, binding = MFR_IMAGE_HEADS) uniform coherent uimage2D uHeads;
uniform uint uPoolSize;

void main() {
  uint index = atomicAdd(allocated, 1u);
  if (index >= uPoolSize) {
    atomicAdd(dropped, 1u);  // overflow: counted, never written out of bounds
    return;
  }
  MfrFragment f = mfrCurrentFragment();
  uint previous = imageAtomicExchange(uHeads, ivec2(gl_FragCoord.xy), index);
  nodeWords[3u * index] = f.color;
  nodeWords[3u * index + 1u] = floatBitsToUint(f.depth);
  nodeWords[3u * index + 2u] = previous;
}
