// Dynamic k+-buffer (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015): depth-complexity
// histogram on the GPU. Each work group bins 256 pixels' n(p) in shared memory, then adds its
// non-zero bins to the global histogram (one global atomic per bin and group, not per pixel).
// Bins 0..KD_BINS-2 are exact; the last one counts n >= KD_BINS-1.
#include "common/bindings.h"

layout(local_size_x = 256) in;

layout(std430, binding = MFR_SSBO_AUX) readonly buffer KDynamicCounts { uint kdCounts[]; };
layout(std430, binding = MFR_SSBO_OFFSETS) buffer KDynamicHistogram { uint kdHistogram[]; };

uniform uint uPixels;

shared uint sBins[KD_BINS];

void main() {
  for (uint b = gl_LocalInvocationIndex; b < uint(KD_BINS); b += 256u) sBins[b] = 0u;
  barrier();
  // Groups on a 2D grid: one dimension holds 65535 groups, 16.7 million pixels (4096x4096 failed).
  uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationIndex;
  if (i < uPixels) atomicAdd(sBins[min(kdCounts[i], uint(KD_BINS) - 1u)], 1u);
  barrier();
  for (uint b = gl_LocalInvocationIndex; b < uint(KD_BINS); b += 256u)
    if (sBins[b] != 0u) atomicAdd(kdHistogram[b], sBins[b]);
}
