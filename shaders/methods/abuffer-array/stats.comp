// A-buffer with fixed-size per-pixel arrays (FreePipe, Liu et al., I3D 2010): statistics pass.
// Reduces the per-pixel arrival counters to: fragments generated, fragments dropped (arrivals past
// the capacity), pixels that overflowed and the largest count (which sizes the arrays when
// slots=0). Per-work-group reduction in shared memory, then one global atomic per group.
#include "common/bindings.h"

layout(local_size_x = 16, local_size_y = 16) in;

layout(r32ui, binding = MFR_IMAGE_COUNTS) uniform readonly uimage2D uCounts;
layout(std430, binding = MFR_SSBO_COUNTER) buffer ArrayStats {
  uint generated;
  uint dropped;
  uint overflowPixels;
  uint maxCount;
};
uniform uint uSlots;
uniform ivec2 uSize;

shared uint sGenerated, sDropped, sOverflow, sMax;

void main() {
  if (gl_LocalInvocationIndex == 0u) {
    sGenerated = 0u;
    sDropped = 0u;
    sOverflow = 0u;
    sMax = 0u;
  }
  memoryBarrierShared();
  barrier();
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (all(lessThan(p, uSize))) {
    uint c = imageLoad(uCounts, p).x;
    if (c > 0u) {
      atomicAdd(sGenerated, c);
      atomicMax(sMax, c);
      if (c > uSlots) {
        atomicAdd(sDropped, c - uSlots);
        atomicAdd(sOverflow, 1u);
      }
    }
  }
  memoryBarrierShared();
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    if (sGenerated > 0u) atomicAdd(generated, sGenerated);
    if (sDropped > 0u) atomicAdd(dropped, sDropped);
    if (sOverflow > 0u) atomicAdd(overflowPixels, sOverflow);
    if (sMax > 0u) atomicMax(maxCount, sMax);
  }
}
