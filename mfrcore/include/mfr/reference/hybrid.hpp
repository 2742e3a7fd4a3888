#pragma once
// Hybrid transparency on the oracle's exact lists (the CPU side of ops/hybrid.glsl):
// Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §3.3, after Maule, Comba, Torchelsen, Bastos, "Hybrid transparency", I3D 2013.
// The k nearest fragments (the core) are composited exactly with "over"; the remaining t (the
// tail) are replaced by their α-weighted average colour with the transmittance (1 − α_avg)^t:
//   α_avg = Σα / t,  τ_tail = (1 − α_avg)^t,  C_tail = (Σ c·α / Σ α)·(1 − τ_tail),
//   C = C_core + τ_core·(C_tail + τ_tail·C_background),  τ_core = Π_core (1 − α).
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/image.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr {

// Σ c·α (per channel, units of 1/255²), Σ α (units of 1/255) and the count of a pixel's tail,
// exact integer sums of the 8-bit stored values — the same numbers the k-buffer's tail hook
// accumulates on the GPU (KBufferTail, shaders/common/kbuffer_array.glsl).
struct HybridTailSums {
  std::uint64_t colorAlpha[3] = {0, 0, 0};
  std::uint64_t alpha = 0;
  std::uint64_t count = 0;
};

// Sums over sorted[k..n).
HybridTailSums hybridTailSums(std::span<const Fragment> sorted, std::uint32_t k);

// Colour and opacity the tail contributes (C_tail, α_tail = 1 − τ_tail); zero for an empty tail
// or one whose fragments are all fully transparent (Σα = 0).
struct HybridTail {
  glm::vec3 color{0.0f};
  float alpha = 0.0f;
};
HybridTail hybridTail(const HybridTailSums& sums);

// The hybrid colour of one pixel from its sorted list (near first) with core size k; k ≥ n is
// exactly compositeOver, k = 0 the pure weighted average. Float, not rounded.
glm::vec3 compositeHybrid(std::span<const Fragment> sorted, std::uint32_t k, glm::vec3 background);

// The hybrid image with a per-pixel core size k(p) (image rows top-down, width*height entries),
// or one k for every pixel; rounded to 8 bits like compositeOver. Throws mfr::Error when the
// map's size does not match the lists.
ImageRGBA8 compositeHybrid(const FragmentLists& lists, std::span<const std::uint32_t> kMap, glm::vec3 background);
ImageRGBA8 compositeHybrid(const FragmentLists& lists, std::uint32_t k, glm::vec3 background);

// The deep hybrid OIT paper's per-pixel error (its eq. 2): the squared colour difference
// ‖hybrid(k) − over(all)‖² of one pixel, in float.
double hybridError(std::span<const Fragment> sorted, std::uint32_t k, glm::vec3 background);

// m(p) per pixel (image rows, width*height entries): how many of the pixel's farthest fragments
// share the farthest one's packed RGBA, and lie strictly behind every fragment of another RGBA
// (0 where n = 0). Hybrid transparency composites such a tail exactly (its weighted average is
// that colour and (1 − α)^m is the over operator's product), so the core needs max(1, n − m) slots.
// The variable-k buffers' tail-run passes compute the same map on the GPU.
std::vector<std::uint32_t> tailRunLengths(const FragmentLists& lists);

// Σ max(1, n(p) − 1) over the non-empty pixels: with that many core slots, k(p) = max(1, n − 1),
// the hybrid image is exact everywhere (a one-fragment tail composites exactly). Given tailRuns
// (tailRunLengths(lists)), Σ max(1, n(p) − m(p)): the least budget of an exact image.
std::uint64_t exactHybridSlots(const FragmentLists& lists, std::span<const std::uint32_t> tailRuns = {});

}  // namespace mfr
