// Exact operations on the oracle's sorted lists: front-to-back "over" compositing and depth
// complexity (the per-pixel fragment count n(p) and its histogram).
#include "mfr/reference/composite.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/packing.hpp>

namespace mfr {

std::vector<std::uint32_t> FragmentLists::counts() const {
  std::vector<std::uint32_t> n(offsets.empty() ? 0 : offsets.size() - 1);
  for (std::size_t i = 0; i < n.size(); ++i) n[i] = offsets[i + 1] - offsets[i];
  return n;
}

std::uint32_t FragmentLists::maxCount() const {
  std::uint32_t m = 0;
  for (std::size_t i = 0; i + 1 < offsets.size(); ++i) m = std::max(m, offsets[i + 1] - offsets[i]);
  return m;
}

glm::vec3 compositeOver(std::span<const Fragment> sorted, const glm::vec3& background) {
  glm::vec3 colour(0.0f);
  float transmittance = 1.0f;
  for (const Fragment& f : sorted) {
    const glm::vec4 c = glm::unpackUnorm4x8(f.color);
    colour += transmittance * c.a * glm::vec3(c);
    transmittance *= 1.0f - c.a;
  }
  return colour + transmittance * background;
}

ImageRGBA8 compositeOver(const FragmentLists& lists, const glm::vec3& background) {
  ImageRGBA8 image(lists.width, lists.height);
  const auto to8 = [](float c) { return static_cast<std::uint8_t>(std::round(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const glm::vec3 c = compositeOver(lists.pixel(x, y), background);
      std::uint8_t* p = image.at(x, y);
      p[0] = to8(c.r);
      p[1] = to8(c.g);
      p[2] = to8(c.b);
      p[3] = 255;
    }
  return image;
}

ImageF depthComplexity(const FragmentLists& lists) {
  ImageF image(lists.width, lists.height, 1);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) image.at(x, y) = static_cast<float>(lists.count(x, y));
  return image;
}

std::vector<std::uint64_t> depthComplexityHistogram(const FragmentLists& lists) {
  std::vector<std::uint64_t> histogram(static_cast<std::size_t>(lists.maxCount()) + 1, 0);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) ++histogram[lists.count(x, y)];
  return histogram;
}

}  // namespace mfr
