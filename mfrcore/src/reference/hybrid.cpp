// Hybrid transparency on exact lists (Tsopouridis, Fudos, Vasilakis, The Visual Computer 2022,
// §3.3; Maule et al., I3D 2013). Same arithmetic, in the same order, as shaders/ops/hybrid.glsl:
// the core like compositeOver, the tail from integer sums of the 8-bit values.
#include "mfr/reference/hybrid.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/packing.hpp>

#include "budget/glsl_shared.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"

namespace mfr {

HybridTailSums hybridTailSums(std::span<const Fragment> sorted, std::uint32_t k) {
  HybridTailSums s;
  for (std::size_t i = k; i < sorted.size(); ++i) {
    const std::uint32_t c = sorted[i].color;
    const std::uint64_t a = (c >> 24) & 0xFFu;
    for (int ch = 0; ch < 3; ++ch) s.colorAlpha[ch] += ((c >> (8 * ch)) & 0xFFu) * a;
    s.alpha += a;
    ++s.count;
  }
  return s;
}

HybridTail hybridTail(const HybridTailSums& sums) {
  HybridTail tail;
  if (sums.count == 0 || sums.alpha == 0) return tail;  // nothing visible behind the core
  const float alphaSum = static_cast<float>(sums.alpha) / 255.0f;
  const float alphaAvg = alphaSum / static_cast<float>(sums.count);
  const float transmittance = std::pow(1.0f - alphaAvg, static_cast<float>(sums.count));
  tail.alpha = 1.0f - transmittance;
  // Σ c·α / Σ α: the α-weighted average colour (the 1/255² and 1/255 units leave one 1/255).
  const glm::vec3 colorAlpha(static_cast<float>(sums.colorAlpha[0]), static_cast<float>(sums.colorAlpha[1]),
                             static_cast<float>(sums.colorAlpha[2]));
  tail.color = colorAlpha / (255.0f * static_cast<float>(sums.alpha)) * tail.alpha;
  return tail;
}

glm::vec3 compositeHybrid(std::span<const Fragment> sorted, std::uint32_t k, glm::vec3 background) {
  const std::size_t core = std::min<std::size_t>(k, sorted.size());
  glm::vec3 colour(0.0f);
  float transmittance = 1.0f;
  for (std::size_t i = 0; i < core; ++i) {
    const glm::vec4 c = glm::unpackUnorm4x8(sorted[i].color);
    colour += transmittance * c.a * glm::vec3(c);
    transmittance *= 1.0f - c.a;
  }
  const HybridTail tail = hybridTail(hybridTailSums(sorted, k));
  return colour + transmittance * (tail.color + (1.0f - tail.alpha) * background);
}

ImageRGBA8 compositeHybrid(const FragmentLists& lists, std::span<const std::uint32_t> kMap, glm::vec3 background) {
  const std::size_t pixels = static_cast<std::size_t>(lists.width) * lists.height;
  if (kMap.size() != pixels)
    throw Error("hybrid k(p) map",
                "has " + std::to_string(kMap.size()) + " entries for " + std::to_string(pixels) + " pixels");
  ImageRGBA8 image(lists.width, lists.height);
  const auto to8 = [](float c) { return static_cast<std::uint8_t>(std::round(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const glm::vec3 c = compositeHybrid(lists.pixel(x, y), kMap[lists.index(x, y)], background);
      std::uint8_t* p = image.at(x, y);
      p[0] = to8(c.r);
      p[1] = to8(c.g);
      p[2] = to8(c.b);
      p[3] = 255;
    }
  return image;
}

ImageRGBA8 compositeHybrid(const FragmentLists& lists, std::uint32_t k, glm::vec3 background) {
  const std::vector<std::uint32_t> kMap(static_cast<std::size_t>(lists.width) * lists.height, k);
  return compositeHybrid(lists, kMap, background);
}

std::vector<std::uint32_t> tailRunLengths(const FragmentLists& lists) {
  std::vector<std::uint32_t> runs(static_cast<std::size_t>(lists.width) * lists.height, 0u);
  for (std::size_t p = 0; p < runs.size(); ++p) {
    const std::span<const Fragment> list = lists.pixel(p);
    if (list.empty()) continue;
    // The farthest colour: the largest packed RGBA at the farthest depth (equal depths have no
    // order), as the GPU's atomicMax picks it; then the fragments strictly behind every fragment
    // of another colour.
    const float far = list.back().depth;
    std::uint32_t farColor = 0;
    for (const Fragment& f : list)
      if (f.depth == far) farColor = std::max(farColor, f.color);
    bool otherColor = false;
    float otherDepth = 0.0f;
    for (const Fragment& f : list)
      if (f.color != farColor) {
        otherColor = true;
        otherDepth = std::max(otherDepth, f.depth);
      }
    runs[p] = otherColor ? static_cast<std::uint32_t>(std::count_if(
                               list.begin(), list.end(), [&](const Fragment& f) { return f.depth > otherDepth; }))
                         : static_cast<std::uint32_t>(list.size());
  }
  return runs;
}

std::uint64_t exactHybridSlots(const FragmentLists& lists, std::span<const std::uint32_t> tailRuns) {
  std::uint64_t slots = 0;
  for (std::size_t p = 0; p + 1 < lists.offsets.size(); ++p)
    slots += glsl::mfrAllocExactK(lists.offsets[p + 1] - lists.offsets[p], tailRuns.empty() ? 1u : tailRuns[p]);
  return slots;
}

double hybridError(std::span<const Fragment> sorted, std::uint32_t k, glm::vec3 background) {
  const glm::dvec3 d =
      glm::dvec3(compositeHybrid(sorted, k, background)) - glm::dvec3(compositeOver(sorted, background));
  return glm::dot(d, d);
}

}  // namespace mfr
