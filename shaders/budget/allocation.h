// [Variable k-buffer allocation — after Vasilakis, Vardis, Papaioannou, Moustakas, "Variable
// k-buffer using Importance Maps", Eurographics 2017 Short Papers, and Tsopouridis, Fudos,
// Vasilakis, "Deep hybrid order-independent transparency", The Visual Computer 2022.]
// The allocation rule from per-pixel importance I(p) to k(p), shared verbatim by the GPU passes
// (shaders/budget/alloc_*.comp) and the C++ reference (mfrcore/src/budget/k_allocation.cpp):
//   k_λ(p) = clamp(floor(λ·I(p)), lower(p), upper(p))   (0 where n(p) = 0)
// with the bounds set once per frame by a mode word (mfr::allocationBounds in mfr/budget/k_allocation.hpp):
//   lower = 1 (MFR_ALLOC_FLOOR_ONE: F holds one slot per non-empty pixel) or 0;
//   upper = e(p) (MFR_ALLOC_CAP_TAIL) or n, where e(p) = max(1, n − m) is the core size from which
//     the pixel's hybrid result is exact: hybrid transparency composites a tail of one fragment
//     exactly (τ = 1 − α, colour = the fragment's), and a tail of m fragments of one colour and
//     opacity too (weighted average = that colour, τ = (1 − α)^m, the over operator's product).
//     m = 1, or with MFR_ALLOC_RUNS the length of the pixel's final run of fragments of one packed
//     RGBA (the tail-run passes, shaders/budget/tail_run_*.geom.frag). Slots beyond e(p) buy
//     nothing while any pixel still lacks its e-th;
//   when F exceeds Σ e(p) (MFR_ALLOC_FILL): lower = e(p), upper = n — every pixel is exact and
//     the remaining slots only use the budget up.
// Σ_p k_λ(p) never decreases with λ. λ is searched over the bit patterns of non-negative floats
// (they order like the floats): MFR_ALLOC_SECTIONS − 1 candidates per round narrow [lo, hi] to
// adjacent floats in MFR_ALLOC_ROUNDS rounds, keeping S(lo) ≤ F < S(hi); the F − S(lo) slots
// left are then given, one pixel after another in pixel order, to the pixels whose k grows
// between lo and hi. So Σk = F exactly whenever Σn ≥ F, where the papers' floor(F·I/ΣI)
// leaves slots unused.
// Valid GLSL 4.50 and C++ (included inside a namespace with uint, floor, min, clamp in scope).
#ifndef MFR_ALLOCATION_H
#define MFR_ALLOCATION_H

#define MFR_ALLOC_SECTIONS 16u
#define MFR_ALLOC_ROUNDS 8u
#define MFR_ALLOC_SEARCH_PIXELS 8u  // pixels per invocation of a search round (alloc_search.comp)
#define MFR_ALLOC_INFINITY_BITS 0x7F800000u
#define MFR_ALLOC_FLOOR_ONE 1u
#define MFR_ALLOC_CAP_TAIL 2u
#define MFR_ALLOC_FILL 4u
#define MFR_ALLOC_RUNS 8u

const float MFR_IMPORTANCE_FLOOR = 1.0e-6f;  // every non-empty pixel keeps a positive importance
const float MFR_ALLOC_MAX_SCALED = 4294967040.0f;  // largest float below 2^32

// NaN, negative and tiny importances become the floor (so λ = +inf reaches k = n everywhere).
float mfrSanitizeImportance(float importance) {
  return importance >= MFR_IMPORTANCE_FLOOR ? importance : MFR_IMPORTANCE_FLOOR;
}

// e = max(1, n − m) for a final run of m ≥ 1 fragments of one colour (0 where n = 0): the slots
// after which a pixel's hybrid result is exact. m = 0 counts as 1 (a one-fragment tail is exact
// whatever its colour).
uint mfrAllocExactK(uint n, uint m) {
  uint run = max(m, 1u);
  return n > run ? n - run : min(n, 1u);
}

uint mfrAllocLower(uint e, uint mode) {
  if ((mode & MFR_ALLOC_FILL) != 0u) return e;
  return (mode & MFR_ALLOC_FLOOR_ONE) != 0u ? 1u : 0u;
}

uint mfrAllocUpper(uint n, uint e, uint mode) {
  return (mode & MFR_ALLOC_CAP_TAIL) != 0u ? e : n;
}

// k_λ(p) for a pixel with n fragments and exact core size e = mfrAllocExactK(n, m).
uint mfrAllocK(float lambda, float importance, uint n, uint e, uint mode) {
  if (n == 0u) return 0u;
  float scaled = min(floor(lambda * importance), MFR_ALLOC_MAX_SCALED);
  return clamp(uint(scaled), mfrAllocLower(e, mode), mfrAllocUpper(n, e, mode));
}

// Candidate j (0..MFR_ALLOC_SECTIONS) between the bit patterns lo ≤ hi: lo + floor((hi − lo)·j / S)
// without 64-bit arithmetic.
uint mfrAllocCandidate(uint lo, uint hi, uint j) {
  uint d = hi - lo;
  return lo + (d / MFR_ALLOC_SECTIONS) * j + ((d % MFR_ALLOC_SECTIONS) * j) / MFR_ALLOC_SECTIONS;
}

#endif
