#pragma once
// The offline optimal per-pixel k(p) under a total slot budget F (Σ_p k(p) ≤ F, 1 ≤ k(p) ≤ n(p)
// where n(p) > 0, k(p) = 0 where n(p) = 0) minimising the total hybrid-transparency error
// Σ_p e_p(k(p)), e_p(k) = ‖hybrid_p(k) − over_p(all)‖² (Tsopouridis, Fudos, Vasilakis, "Deep
// hybrid order-independent transparency", The Visual Computer 2022, eq. 2 and Alg. 1).
// Three solvers on the same per-pixel error table:
//   greedy      the paper's backward greedy (Alg. 1): start at k(p) = n(p), repeatedly take one
//               slot from the pixel whose error grows least (a min-heap of marginal errors).
//               O(Σn log P). Optimal when every e_p is convex in k (its Lemma 1's premise);
//               tests/unit/test_optimal_k.cpp shows it is not in general.
//   dynamic     exact: a knapsack over pixels, dp[i][b] = least error of pixels < i with b slots.
//               O(P · F · max n) time, O(P · F) memory: small cases only.
//   lagrangian  exact on the lower convex hulls: for a multiplier μ every pixel takes the k
//               minimising e_p(k) + μ·k; μ is bisected to the smallest that fits F; the slots
//               left are then given one by one where they lower the error most. O(Σn · 100).
//               Exact whenever its hull points sum to F; it does not depend on convexity, so it
//               beats the greedy where e_p has bumps (and the greedy wins elsewhere, rarely).
//   best        the lower-error allocation of greedy and lagrangian: the optimal-k reference
//               (mfr render --method optimal-k, the training labels of mfr dataset).
//   exhaustive  every k vector; tiny cases (tests).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/reference/oracle.hpp"

namespace mfr {

// errors[p][k] = e_p(k) for k = 0..n(p) (errors[p].size() = n(p) + 1; e_p(n(p)) = 0).
using HybridErrorTable = std::vector<std::vector<double>>;

// The table of the oracle's lists (pixel index = lists.index(x, y)), with hybridError().
HybridErrorTable hybridErrorTable(const FragmentLists& lists, glm::vec3 background);

struct KAllocation {
  std::vector<std::uint32_t> k;  // per pixel
  double error = 0.0;            // Σ_p e_p(k(p))
  std::uint64_t slots = 0;       // Σ_p k(p)
};

// The least budget any solver accepts: one slot per non-empty pixel.
std::uint64_t minimumSlots(const HybridErrorTable& errors);
// Total error of an allocation (k.size() must equal errors.size()).
double allocationError(const HybridErrorTable& errors, const std::vector<std::uint32_t>& k);

// The table with each pixel's curve replaced by the mean curve of all pixels of the same depth
// complexity n(p): what an allocation can know of a pixel that sees only n(p), not its colours.
// optimalKBest on it is the best allocation that treats pixels of equal n alike in expectation —
// the training labels of `mfr dataset --labels class-optimal` (docs/methods.md, "dkb training data").
// group (optional, one entry per pixel) splits the classes further: pixels are alike when both
// n(p) and group[p] agree (mfr allocations groups by whether the two farthest fragments share a
// colour). Throws mfr::Error when group has another size than errors.
HybridErrorTable classMeanErrorTable(const HybridErrorTable& errors, std::span<const std::uint32_t> group = {});

// Each throws mfr::Error("budget F", …) when budget < minimumSlots(errors); a budget ≥ Σ n(p)
// gives k = n everywhere (error 0).
KAllocation optimalKGreedy(const HybridErrorTable& errors, std::uint64_t budget);
KAllocation optimalKDynamic(const HybridErrorTable& errors, std::uint64_t budget);
KAllocation optimalKLagrangian(const HybridErrorTable& errors, std::uint64_t budget);
// solver (optional) receives "greedy" or "lagrangian".
KAllocation optimalKBest(const HybridErrorTable& errors, std::uint64_t budget, std::string* solver = nullptr);
// Also throws when the number of candidate vectors (Π n(p)) exceeds maxCandidates.
KAllocation optimalKExhaustive(const HybridErrorTable& errors, std::uint64_t budget,
                               std::uint64_t maxCandidates = 10'000'000);

}  // namespace mfr
