// Optimal per-pixel k under a slot budget: the deep hybrid OIT paper's backward greedy (Alg. 1;
// Tsopouridis, Fudos, Vasilakis, The Visual Computer 2022), an exact knapsack DP and an
// exhaustive search (see mfr/budget/optimal_k.hpp).
#include "mfr/budget/optimal_k.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>

#include <glm/gtc/packing.hpp>

#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"

namespace mfr {

namespace {

std::uint32_t listLength(const std::vector<double>& e) {
  return static_cast<std::uint32_t>(e.size() - 1);
}

void checkBudget(const HybridErrorTable& errors, std::uint64_t budget) {
  for (const auto& e : errors)
    if (e.empty()) throw Error("hybrid error table", "a pixel has no e(0) entry");
  const std::uint64_t need = minimumSlots(errors);
  if (budget < need)
    throw Error("budget F=" + std::to_string(budget),
                "below one slot per non-empty pixel (" + std::to_string(need) + " slots)");
}

KAllocation finish(const HybridErrorTable& errors, std::vector<std::uint32_t> k) {
  KAllocation a;
  a.error = allocationError(errors, k);
  a.slots = std::accumulate(k.begin(), k.end(), std::uint64_t{0});
  a.k = std::move(k);
  return a;
}

}  // namespace

HybridErrorTable hybridErrorTable(const FragmentLists& lists, glm::vec3 background) {
  // O(n) per pixel: the core's colour and transmittance as running products (the order
  // compositeHybrid uses, so the values are the same floats) and the tail's integer sums as
  // running suffix sums; e(k) = ‖hybrid(k) − over(all)‖² like hybridError().
  HybridErrorTable table(static_cast<std::size_t>(lists.width) * lists.height);
  std::vector<HybridTailSums> suffix;
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const auto list = lists.pixel(x, y);
      const std::size_t n = list.size();
      auto& e = table[lists.index(x, y)];
      e.assign(n + 1, 0.0);
      suffix.assign(n + 1, HybridTailSums{});
      for (std::size_t i = n; i-- > 0;) {
        suffix[i] = suffix[i + 1];
        const std::uint32_t c = list[i].color;
        const std::uint64_t a = (c >> 24) & 0xFFu;
        for (int ch = 0; ch < 3; ++ch) suffix[i].colorAlpha[ch] += ((c >> (8 * ch)) & 0xFFu) * a;
        suffix[i].alpha += a;
        ++suffix[i].count;
      }
      const glm::dvec3 exact(compositeOver(list, background));
      glm::vec3 colour(0.0f);
      float transmittance = 1.0f;
      for (std::size_t k = 0; k <= n; ++k) {
        const HybridTail tail = hybridTail(suffix[k]);
        const glm::vec3 h = colour + transmittance * (tail.color + (1.0f - tail.alpha) * background);
        const glm::dvec3 d = glm::dvec3(h) - exact;
        e[k] = glm::dot(d, d);
        if (k < n) {
          const glm::vec4 c = glm::unpackUnorm4x8(list[k].color);
          colour += transmittance * c.a * glm::vec3(c);
          transmittance *= 1.0f - c.a;
        }
      }
    }
  return table;
}

std::uint64_t minimumSlots(const HybridErrorTable& errors) {
  return static_cast<std::uint64_t>(
      std::count_if(errors.begin(), errors.end(), [](const std::vector<double>& e) { return e.size() > 1; }));
}

double allocationError(const HybridErrorTable& errors, const std::vector<std::uint32_t>& k) {
  double sum = 0.0;
  for (std::size_t p = 0; p < errors.size(); ++p) sum += errors[p][k[p]];
  return sum;
}

HybridErrorTable classMeanErrorTable(const HybridErrorTable& errors, std::span<const std::uint32_t> group) {
  if (!group.empty() && group.size() != errors.size())
    throw Error("class mean error table",
                std::to_string(group.size()) + " groups for " + std::to_string(errors.size()) + " pixels");
  // (n + 1, group) → (Σ curves, pixels)
  std::map<std::pair<std::size_t, std::uint32_t>, std::pair<std::vector<double>, std::size_t>> classes;
  auto key = [&](std::size_t p) { return std::make_pair(errors[p].size(), group.empty() ? 0u : group[p]); };
  for (std::size_t p = 0; p < errors.size(); ++p) {
    auto& [sum, count] = classes[key(p)];
    if (sum.empty()) sum.assign(errors[p].size(), 0.0);
    for (std::size_t k = 0; k < errors[p].size(); ++k) sum[k] += errors[p][k];
    ++count;
  }
  for (auto& [size, c] : classes)
    for (double& v : c.first) v /= static_cast<double>(c.second);
  HybridErrorTable out;
  out.reserve(errors.size());
  for (std::size_t p = 0; p < errors.size(); ++p) out.push_back(classes.at(key(p)).first);
  return out;
}

KAllocation optimalKGreedy(const HybridErrorTable& errors, std::uint64_t budget) {
  checkBudget(errors, budget);
  std::vector<std::uint32_t> k(errors.size());
  std::uint64_t slots = 0;
  // Min-heap of (error increase of taking one slot from pixel p, p); ties go to the lower index.
  using Entry = std::tuple<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  for (std::size_t p = 0; p < errors.size(); ++p) {
    k[p] = listLength(errors[p]);
    slots += k[p];
    if (k[p] > 1) heap.emplace(errors[p][k[p] - 1] - errors[p][k[p]], p);
  }
  while (slots > budget && !heap.empty()) {  // checkBudget guarantees the heap outlasts the excess
    const std::size_t p = std::get<1>(heap.top());
    heap.pop();
    --k[p];
    --slots;
    if (k[p] > 1) heap.emplace(errors[p][k[p] - 1] - errors[p][k[p]], p);
  }
  return finish(errors, std::move(k));
}

KAllocation optimalKDynamic(const HybridErrorTable& errors, std::uint64_t budget) {
  checkBudget(errors, budget);
  std::uint64_t total = 0;
  for (const auto& e : errors) total += listLength(e);
  const std::size_t cap = static_cast<std::size_t>(std::min(budget, total));
  const std::size_t pixels = errors.size();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // dp[b] = least error of the pixels so far using exactly b slots; choice[i][b] = k of pixel i.
  std::vector<double> dp(cap + 1, kInf), next(cap + 1);
  dp[0] = 0.0;
  std::vector<std::vector<std::uint32_t>> choice(pixels, std::vector<std::uint32_t>(cap + 1, 0));
  for (std::size_t i = 0; i < pixels; ++i) {
    const std::uint32_t n = listLength(errors[i]);
    const std::uint32_t kMin = n > 0 ? 1 : 0;
    std::fill(next.begin(), next.end(), kInf);
    for (std::size_t b = 0; b <= cap; ++b) {
      if (dp[b] == kInf) continue;
      for (std::uint32_t k = kMin; k <= n && b + k <= cap; ++k) {
        const double v = dp[b] + errors[i][k];
        if (v < next[b + k]) {
          next[b + k] = v;
          choice[i][b + k] = k;
        }
      }
    }
    dp.swap(next);
  }
  std::size_t best = 0;
  for (std::size_t b = 0; b <= cap; ++b)
    if (dp[b] < dp[best]) best = b;
  std::vector<std::uint32_t> k(pixels);
  for (std::size_t i = pixels; i-- > 0;) {
    k[i] = choice[i][best];
    best -= k[i];
  }
  return finish(errors, std::move(k));
}

KAllocation optimalKLagrangian(const HybridErrorTable& errors, std::uint64_t budget) {
  checkBudget(errors, budget);
  const std::size_t pixels = errors.size();
  std::uint64_t total = 0;
  double muHigh = 1.0;
  for (const auto& e : errors) {
    total += listLength(e);
    if (e.size() > 1) muHigh = std::max(muHigh, 2.0 * e[1] + 1.0);
  }
  std::vector<std::uint32_t> k(pixels);
  if (total <= budget) {
    for (std::size_t p = 0; p < pixels; ++p) k[p] = listLength(errors[p]);
    return finish(errors, std::move(k));
  }
  // k_p(μ) = argmin over 1 ≤ k ≤ n of e_p(k) + μ·k (the smallest on ties): a point of the lower
  // convex hull of e_p. Σ k_p(μ) never increases with μ; at muHigh every pixel takes k = 1 (each
  // further slot saves less than e_p(1) < μ).
  const auto pick = [&](double mu, std::vector<std::uint32_t>& out) {
    std::uint64_t sum = 0;
    for (std::size_t p = 0; p < pixels; ++p) {
      const auto& e = errors[p];
      const std::uint32_t n = listLength(e);
      std::uint32_t best = n > 0 ? 1 : 0;
      double bestCost = e[best] + mu * best;
      for (std::uint32_t c = best + 1; c <= n; ++c) {
        const double cost = e[c] + mu * c;
        if (cost < bestCost) {
          bestCost = cost;
          best = c;
        }
      }
      out[p] = best;
      sum += best;
    }
    return sum;
  };
  double lo = 0.0, hi = muHigh;  // S(lo) > budget ≥ S(hi)
  std::vector<std::uint32_t> kHi(pixels);
  pick(hi, kHi);
  for (int it = 0; it < 100 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (pick(mid, k) <= budget) {
      hi = mid;
      kHi = k;
    } else {
      lo = mid;
    }
  }
  k = kHi;
  // The slots the hull points leave: one at a time where they lower the error most.
  std::uint64_t slots = std::accumulate(k.begin(), k.end(), std::uint64_t{0});
  using Entry = std::tuple<double, std::size_t>;
  std::priority_queue<Entry> gains;
  for (std::size_t p = 0; p < pixels; ++p)
    if (k[p] < listLength(errors[p])) gains.emplace(errors[p][k[p]] - errors[p][k[p] + 1], p);
  while (slots < budget && !gains.empty()) {
    const auto [gain, p] = gains.top();
    gains.pop();
    if (gain <= 0.0) break;
    ++k[p];
    ++slots;
    if (k[p] < listLength(errors[p])) gains.emplace(errors[p][k[p]] - errors[p][k[p] + 1], p);
  }
  return finish(errors, std::move(k));
}

KAllocation optimalKBest(const HybridErrorTable& errors, std::uint64_t budget, std::string* solver) {
  KAllocation greedy = optimalKGreedy(errors, budget);
  KAllocation hull = optimalKLagrangian(errors, budget);
  const bool hullWins = hull.error < greedy.error;
  if (solver) *solver = hullWins ? "lagrangian" : "greedy";
  return hullWins ? hull : greedy;
}

KAllocation optimalKExhaustive(const HybridErrorTable& errors, std::uint64_t budget, std::uint64_t maxCandidates) {
  checkBudget(errors, budget);
  std::uint64_t candidates = 1;
  for (const auto& e : errors) {
    candidates *= std::max<std::uint64_t>(listLength(e), 1);
    if (candidates > maxCandidates)
      throw Error("exhaustive optimal k", "more than " + std::to_string(maxCandidates) + " candidate allocations");
  }
  const std::size_t pixels = errors.size();
  std::vector<std::uint32_t> k(pixels), best;
  for (std::size_t p = 0; p < pixels; ++p) k[p] = listLength(errors[p]) > 0 ? 1 : 0;
  double bestError = std::numeric_limits<double>::infinity();
  for (std::uint64_t c = 0; c < candidates; ++c) {
    const std::uint64_t slots = std::accumulate(k.begin(), k.end(), std::uint64_t{0});
    if (slots <= budget) {
      const double e = allocationError(errors, k);
      if (e < bestError) {
        bestError = e;
        best = k;
      }
    }
    // Next vector, odometer order.
    for (std::size_t p = 0; p < pixels; ++p) {
      if (k[p] < listLength(errors[p])) {
        ++k[p];
        break;
      }
      k[p] = listLength(errors[p]) > 0 ? 1 : 0;
    }
  }
  return finish(errors, std::move(best));
}

}  // namespace mfr
