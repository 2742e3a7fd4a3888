#include "mfr/reference/probe.hpp"

#include <cmath>
#include <limits>

#include "mfr/reference/composite.hpp"

namespace mfr {

std::uint32_t PixelProbe::heldCount() const {
  std::uint32_t n = 0;
  for (const ProbeFragment& f : fragments) n += f.held ? 1u : 0u;
  return n;
}

PixelProbe probePixel(const Scene& scene, const Camera& camera, int width, int height, int x, int y,
                      const OracleOptions& options) {
  OracleOptions one = options;
  one.region = {x, y, 1, 1};
  const FragmentLists lists = castFragments(scene, camera, width, height, one);

  PixelProbe probe;
  probe.x = x;
  probe.y = y;
  probe.width = width;
  probe.height = height;
  probe.edge = (lists.flags[lists.index(x, y)] & FragmentLists::kEdge) != 0;
  probe.depthTie = (lists.flags[lists.index(x, y)] & FragmentLists::kDepthTie) != 0;
  const std::span<const Fragment> sorted = lists.pixel(x, y);
  const glm::dvec4 toEye = camera.depthToEye();
  double transmittance = 1.0;
  for (const Fragment& f : sorted) {
    const double ndc = 2.0 * f.depth - 1.0;
    const double alpha = glm::unpackUnorm4x8(f.color).a;
    ProbeFragment p;
    p.fragment = f;
    p.eyeDepth = -(toEye.x * ndc + toEye.y) / (toEye.z * ndc + toEye.w);
    p.weight = transmittance * alpha;
    transmittance *= 1.0 - alpha;
    probe.fragments.push_back(p);
  }
  probe.transmittance = transmittance;
  probe.exactColor = compositeOver(sorted, scene.background);
  return probe;
}

void matchCapture(PixelProbe& probe, std::span<const Fragment> fragments, std::uint32_t count, double depthTolerance) {
  probe.captured = true;
  probe.methodCount = count;
  probe.methodFragments.assign(fragments.begin(), fragments.end());
  probe.unmatched = 0;
  for (ProbeFragment& f : probe.fragments) f.held = false;
  for (const Fragment& got : fragments) {
    const double tol = depthTolerance * std::max(1.0, std::abs(static_cast<double>(got.depth)));
    ProbeFragment* best = nullptr;
    double bestDepth = std::numeric_limits<double>::infinity();
    int bestColour = 0;
    for (ProbeFragment& f : probe.fragments) {
      if (f.held) continue;
      const double d = std::abs(static_cast<double>(f.fragment.depth) - got.depth);
      if (d > tol) continue;
      const glm::ivec4 a(glm::round(glm::unpackUnorm4x8(f.fragment.color) * 255.0f));
      const glm::ivec4 b(glm::round(glm::unpackUnorm4x8(got.color) * 255.0f));
      const glm::ivec4 diff = glm::abs(a - b);
      const int colour = std::max(std::max(diff.x, diff.y), std::max(diff.z, diff.w));
      if (best == nullptr || d < bestDepth || (d == bestDepth && colour < bestColour)) {
        best = &f;
        bestDepth = d;
        bestColour = colour;
      }
    }
    if (best != nullptr)
      best->held = true;
    else
      ++probe.unmatched;
  }
}

}  // namespace mfr
