// Work-efficient parallel exclusive scan (prefix sum) of uints: Blelloch, "Prefix Sums and Their
// Applications", CMU-CS-90-190 (1990), in the GPU layout of Harris, Sengupta, Owens, "Parallel
// Prefix Sum (Scan) with CUDA", GPU Gems 3, ch. 39 (2007): each work group scans one block in
// shared memory (up-sweep + down-sweep) and writes the block's total; the C++ side
// (mfrcore/src/methods/prefix_sum.cpp) scans the block totals with this same pass, level by level,
// then the MFR_SCAN_ADD variant adds each block's scanned offset to its elements. O(n) work, no
// serial loop over the data, no CPU round trip.
//
// Bindings (held only during the dispatch; callers re-bind their own buffers afterwards):
//   MFR_SSBO_AUX      input elements   (uInBase = first element)
//   MFR_SSBO_OFFSETS  output elements  (uOutBase; may be the input buffer itself)
//   MFR_SSBO_SCAN     block totals     (uSumsBase; the last level's single total = grand total)
#include "common/bindings.h"

#define SCAN_THREADS 256u
#define SCAN_PER_THREAD 4u
#define SCAN_BLOCK (SCAN_THREADS * SCAN_PER_THREAD)  // must equal PrefixSum::kBlock

layout(local_size_x = 256) in;

layout(std430, binding = MFR_SSBO_AUX) buffer ScanIn { uint scanIn[]; };
layout(std430, binding = MFR_SSBO_OFFSETS) buffer ScanOut { uint scanOut[]; };
layout(std430, binding = MFR_SSBO_SCAN) buffer ScanSums { uint scanSums[]; };

uniform uint uCount;     // elements at this level
uniform uint uBlocks;    // blocks at this level (work groups beyond it return at once)
uniform uint uInBase;
uniform uint uOutBase;
uniform uint uSumsBase;

// Blocks may exceed the 65535 work groups of one dispatch dimension: the grid is 2D.
uint blockIndex() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }

#ifdef MFR_SCAN_ADD

void main() {
  uint b = blockIndex();
  if (b >= uBlocks) return;
  uint add = scanSums[uSumsBase + b];
  uint base = b * SCAN_BLOCK;
  for (uint k = 0u; k < SCAN_PER_THREAD; ++k) {
    uint i = base + k * SCAN_THREADS + gl_LocalInvocationID.x;
    if (i < uCount) scanOut[uOutBase + i] += add;
  }
}

#else

// One padding word per 32 (Harris et al. §39.2.3): the per-thread runs of SCAN_PER_THREAD
// consecutive words would otherwise hit the same shared-memory banks.
shared uint sData[SCAN_BLOCK + SCAN_BLOCK / 32u];
shared uint sThread[SCAN_THREADS];
shared uint sTotal;

uint pad(uint i) { return i + (i >> 5u); }

void main() {
  uint b = blockIndex();
  if (b >= uBlocks) return;  // uniform across the work group: no barrier is skipped by some only
  uint t = gl_LocalInvocationID.x;
  uint base = b * SCAN_BLOCK;

  // Coalesced loads; elements past the end read as 0 (they never change the sums).
  for (uint k = 0u; k < SCAN_PER_THREAD; ++k) {
    uint local = k * SCAN_THREADS + t;
    uint i = base + local;
    sData[pad(local)] = i < uCount ? scanIn[uInBase + i] : 0u;
  }
  memoryBarrierShared();
  barrier();

  // Each thread scans its own run of SCAN_PER_THREAD consecutive elements sequentially.
  uint sum = 0u;
  for (uint k = 0u; k < SCAN_PER_THREAD; ++k) {
    uint j = pad(t * SCAN_PER_THREAD + k);
    uint v = sData[j];
    sData[j] = sum;
    sum += v;
  }
  sThread[t] = sum;
  memoryBarrierShared();
  barrier();

  // Blelloch up-sweep (reduce) over the per-thread totals.
  for (uint d = 1u; d < SCAN_THREADS; d <<= 1u) {
    uint ai = (t + 1u) * 2u * d - 1u;
    if (ai < SCAN_THREADS) sThread[ai] += sThread[ai - d];
    memoryBarrierShared();
    barrier();
  }
  if (t == 0u) {
    sTotal = sThread[SCAN_THREADS - 1u];
    sThread[SCAN_THREADS - 1u] = 0u;
  }
  memoryBarrierShared();
  barrier();
  // Down-sweep: turns the reduction tree into the exclusive scan of the per-thread totals.
  for (uint d = SCAN_THREADS / 2u; d > 0u; d >>= 1u) {
    uint ai = (t + 1u) * 2u * d - 1u;
    if (ai < SCAN_THREADS) {
      uint left = sThread[ai - d];
      sThread[ai - d] = sThread[ai];
      sThread[ai] += left;
    }
    memoryBarrierShared();
    barrier();
  }

  uint offset = sThread[t];
  for (uint k = 0u; k < SCAN_PER_THREAD; ++k) sData[pad(t * SCAN_PER_THREAD + k)] += offset;
  memoryBarrierShared();
  barrier();

  for (uint k = 0u; k < SCAN_PER_THREAD; ++k) {
    uint local = k * SCAN_THREADS + t;
    uint i = base + local;
    if (i < uCount) scanOut[uOutBase + i] = sData[pad(local)];
  }
  if (t == 0u) scanSums[uSumsBase + b] = sTotal;
}

#endif
