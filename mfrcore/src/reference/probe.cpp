#include "mfr/reference/probe.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "mfr/reference/composite.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/render.hpp"

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

void splitHybrid(PixelProbe& probe, glm::vec3 background) {
  probe.hybrid = true;
  std::vector<Fragment> tail;
  for (const ProbeFragment& f : probe.fragments)
    if (!f.held) tail.push_back(f.fragment);
  // The tail's colour and opacity from the exact 8-bit sums, as the GPU's tail hook and
  // compositeHybrid have them.
  const HybridTailSums sums = hybridTailSums(tail, 0);
  const HybridTail tailPart = hybridTail(sums);
  glm::dvec3 colour(0.0);
  double transmittance = 1.0;  // τ_core
  for (ProbeFragment& f : probe.fragments) {
    if (!f.held) continue;
    const glm::dvec4 c(glm::unpackUnorm4x8(f.fragment.color));
    f.hybridWeight = transmittance * c.a;
    colour += f.hybridWeight * glm::dvec3(c);
    transmittance *= 1.0 - c.a;
  }
  for (ProbeFragment& f : probe.fragments) {
    if (f.held) continue;
    const std::uint64_t alpha = (f.fragment.color >> 24) & 0xffu;  // the sums' units: 1/255
    f.hybridWeight =
        sums.alpha == 0 ? 0.0
                        : transmittance * static_cast<double>(alpha) / static_cast<double>(sums.alpha) * tailPart.alpha;
  }
  colour += transmittance * glm::dvec3(tailPart.color);
  probe.hybridBackground = transmittance * (1.0 - tailPart.alpha);
  probe.hybridColor = glm::vec3(colour + probe.hybridBackground * glm::dvec3(background));
}

void splitVolume(PixelProbe& probe, const Scene& scene, const Camera& camera, const RenderRequest& request) {
  const std::vector<Volume> drawn = volumesAsRequested(request, scene);
  if (drawn.empty()) throw Error("--op volume", "scene '" + scene.name + "' has no visible volume");
  const VolumeRaySetup setup = volumeRaySetup(drawn, camera, probe.width, probe.height, volumeStepOf(request, drawn),
                                              scene.clipBox, scene.section);
  std::vector<Fragment> sorted;
  for (const ProbeFragment& f : probe.fragments) sorted.push_back(f.fragment);
  const VolumeBreakdown b =
      compositeVolumeBreakdown(sorted, probe.x, probe.height - 1 - probe.y, setup, scene.background);
  probe.volume = true;
  probe.volumeNames.clear();
  for (const Volume& v : drawn) probe.volumeNames.push_back(v.name);
  for (std::size_t i = 0; i < probe.fragments.size(); ++i) probe.fragments[i].volumeWeight = b.surfaceWeight[i];
  probe.medium.clear();
  for (std::size_t i = 0; i < b.mediumColor.size(); ++i)
    probe.medium.push_back({b.mediumColor[i], b.mediumWeight[i],
                            std::vector<double>(b.mediumWeightByVolume[i].begin(), b.mediumWeightByVolume[i].end())});
  probe.volumeColor = b.color;
  probe.volumeBackground = b.backgroundWeight;
}

void splitZThickness(PixelProbe& probe, const Scene& scene, const Camera& camera, const RenderRequest& request) {
  const double thickness = zThicknessOf(request, scene.bounds());
  std::vector<Fragment> sorted;
  for (const ProbeFragment& f : probe.fragments) sorted.push_back(f.fragment);
  const ZThicknessBreakdown b = compositeZThicknessBreakdown(sorted, glm::vec4(camera.depthToEye()),
                                                             static_cast<float>(thickness), scene.background);
  probe.zthickness = true;
  probe.thickness = thickness;
  for (std::size_t i = 0; i < probe.fragments.size(); ++i) probe.fragments[i].zthicknessWeight = b.weights[i];
  probe.zthicknessColor = b.color;
  probe.zthicknessBackground = b.transmittance;
  probe.zthicknessBlended = 0;
  const auto near = [&](std::size_t a, std::size_t c) {
    return probe.fragments[c].eyeDepth - probe.fragments[a].eyeDepth < thickness;
  };
  for (std::size_t i = 0; i < probe.fragments.size(); ++i)
    if ((i > 0 && near(i - 1, i)) || (i + 1 < probe.fragments.size() && near(i, i + 1))) ++probe.zthicknessBlended;
}

}  // namespace mfr
