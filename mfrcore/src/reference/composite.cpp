// Exact operations on the oracle's sorted lists: front-to-back "over" compositing, image-space CSG
// (each pixel's visible fragment, csgVisibleFragment) and depth complexity (the per-pixel fragment
// count n(p) and its histogram).
#include "mfr/reference/composite.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/gtc/packing.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"

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

namespace {

// Display value → 8 bits, as every composite image rounds.
std::uint8_t to8(float c) {
  return static_cast<std::uint8_t>(std::round(std::clamp(c, 0.0f, 1.0f) * 255.0f));
}

void store(ImageRGBA8& image, int x, int y, const glm::vec3& c) {
  std::uint8_t* p = image.at(x, y);
  p[0] = to8(c.r);
  p[1] = to8(c.g);
  p[2] = to8(c.b);
  p[3] = 255;
}

}  // namespace

namespace {

// The open slabs of one pixel (shaders/ops/zthickness.glsl: a window of MFR_ZTHICK_WINDOW, ends
// ascending) and the integration state.
struct ZThicknessState {
  struct Slab {
    float end = 0.0f;
    float sigma = 0.0f;
    glm::vec3 emission{0.0f};
  };
  std::array<Slab, MFR_ZTHICK_WINDOW> window{};
  std::size_t first = 0, count = 0;
  glm::vec3 colour{0.0f};
  float transmittance = 1.0f;
  float position = 0.0f;

  Slab& slab(std::size_t i) { return window[(first + i) % window.size()]; }

  void integrate(float z) {
    if (z <= position) return;
    float sigma = 0.0f;
    glm::vec3 emission(0.0f);
    for (std::size_t i = 0; i < count; ++i) {
      sigma += slab(i).sigma;
      emission += slab(i).emission;
    }
    if (sigma > 0.0f) {
      const float absorbed = 1.0f - std::exp(-sigma * (z - position));
      colour += transmittance * absorbed * (emission / sigma);
      transmittance *= 1.0f - absorbed;
    }
    position = z;
  }

  void closeUntil(float z) {
    while (count > 0 && slab(0).end <= z) {
      integrate(slab(0).end);
      first = (first + 1) % window.size();
      --count;
    }
  }
};

}  // namespace

glm::vec3 compositeZThickness(std::span<const Fragment> sorted, const glm::vec4& depthToEye, float thickness,
                              const glm::vec3& background) {
  ZThicknessState s;
  for (const Fragment& f : sorted) {
    const glm::vec4 c = glm::unpackUnorm4x8(f.color);
    const float alpha = std::min(c.a, static_cast<float>(MFR_ZTHICK_MAX_ALPHA));
    if (alpha <= 0.0f) continue;
    const float ndc = 2.0f * f.depth - 1.0f;
    const float z = -(depthToEye.x * ndc + depthToEye.y) / (depthToEye.z * ndc + depthToEye.w);
    s.closeUntil(z);
    if (s.count == 0) s.position = z;
    s.integrate(z);
    const float sigma = -std::log(1.0f - alpha) / thickness;
    if (s.count == s.window.size()) {
      ZThicknessState::Slab& newest = s.slab(s.count - 1);
      newest.sigma += sigma;
      newest.emission += sigma * glm::vec3(c);
      continue;
    }
    s.slab(s.count) = {z + thickness, sigma, sigma * glm::vec3(c)};
    ++s.count;
  }
  s.closeUntil(std::numeric_limits<float>::max());
  return s.colour + s.transmittance * background;
}

ImageRGBA8 compositeOver(const FragmentLists& lists, const glm::vec3& background) {
  ImageRGBA8 image(lists.width, lists.height);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) store(image, x, y, compositeOver(lists.pixel(x, y), background));
  return image;
}

ImageRGBA8 compositeZThickness(const FragmentLists& lists, const Camera& camera, double thickness,
                               const glm::vec3& background) {
  if (!std::isfinite(thickness) || thickness <= 0.0)
    throw Error("--thickness", "must be a positive length in scene units (got " + std::to_string(thickness) + ")");
  const glm::vec4 toEye(camera.depthToEye());
  ImageRGBA8 image(lists.width, lists.height);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x)
      store(image, x, y, compositeZThickness(lists.pixel(x, y), toEye, static_cast<float>(thickness), background));
  return image;
}

ImageRGBA8 compositeCsg(const FragmentLists& lists, const Scene& scene) {
  const CsgTree& tree = scene.csg;
  const glm::vec3& background = scene.background;
  if (tree.empty()) throw Error("operation csg", "the scene has no CSG tree");
  const std::uint32_t mirrored = csgMirroredPrimitives(scene);
  ImageRGBA8 image(lists.width, lists.height);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const std::span<const Fragment> sorted = lists.pixel(x, y);
      const std::optional<std::size_t> visible = csgVisibleFragment(tree, sorted, mirrored);
      store(image, x, y, visible ? glm::vec3(glm::unpackUnorm4x8(sorted[*visible].color)) : background);
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
