// [Variable k-buffer storage — Vasilakis, Vardis, Papaioannou, Moustakas, "Variable k-buffer using
// Importance Maps", EG 2017 Short Papers; Tsopouridis, Fudos, Vasilakis, "Deep hybrid
// order-independent transparency", The Visual Computer 2022.] The per-pixel arena of the
// variable-k buffers (vkb, dkb) and their per-frame budget state. One buffer of words, reused
// pass after pass so the budget pays for the largest phase only (mfrcore/src/methods/
// variable_k_buffer.hpp has the layout):
//   N(p)      fragment count n(p)                 → the spin-lock word in the store pass
//   T(i, p)   i = 0..4: features / importance    → the tail sums (5 interleaved words per pixel)
//   K(p)      nearest colour (dkb) → tail run m(p) → k(p) → the prefix-sum offsets of the store pass
#ifndef MFR_ARENA_GLSL
#define MFR_ARENA_GLSL
#include "budget/allocation.h"
#include "common/bindings.h"

layout(std430, binding = MFR_SSBO_ARENA) coherent buffer VariableKArena { uint arena[]; };

// Per-frame state (32 words, cleared and partly written by the C++ side).
layout(std430, binding = MFR_SSBO_BUDGET) coherent buffer VariableKBudget {
  uint vkTotalFragments;  // Σ n(p)
  uint vkNonEmpty;        // pixels with n(p) > 0
  uint vkImageNearBits;   // min over pixels of the nearest depth (float bits)
  uint vkImageFarBits;    // max over pixels of the farthest depth (float bits)
  uint vkBudgetSlots;     // F: slots to assign, min(F(M), Σn)
  uint vkAllocMode;       // MFR_ALLOC_* bounds of k(p) (budget/allocation.h)
  uint vkLo;              // λ search interval, float bit patterns
  uint vkHi;
  uint vkSumLo;           // S(lo)
  uint vkMultiFragment;   // pixels with n(p) > 1
  uint vkSums[15];        // S at the candidates j = 1..15 of the current round
  uint vkKMin;            // over non-empty pixels, after the allocation
  uint vkKMax;
  uint vkExactSlots;      // Σ max(1, n − m) after the tail-run passes
  uint vkReserved[4];
};

uniform uint uVkPixels;  // W*H
uniform int uVkWidth;
uniform uint uVkLockBase;
uniform uint uVkTailBase;
uniform uint uVkStride;  // words between the T(i) regions
uniform uint uVkKBase;

uint vkPixel(ivec2 p) { return uint(p.y) * uint(uVkWidth) + uint(p.x); }
uint vkN(uint p) { return uVkLockBase + p; }
uint vkT(uint i, uint p) { return uVkTailBase + i * uVkStride + p; }
uint vkK(uint p) { return uVkKBase + p; }

// e(p) of the allocation rule: with MFR_ALLOC_RUNS the tail-run passes left m(p) in K(p), which
// the assign pass then overwrites.
uint vkExactK(uint p, uint n) {
  return mfrAllocExactK(n, (vkAllocMode & MFR_ALLOC_RUNS) != 0u ? arena[vkK(p)] : 1u);
}

// Compute passes over pixels: `size` per work group on a 2D grid (one dimension holds 65535 groups).
// A macro, so that fragment shaders including this file never see compute built-ins.
#define VK_INVOCATION_PIXEL(size) \
  ((gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * (size) + gl_LocalInvocationIndex)
#endif
