#include "mfr/reference/probe.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "mfr/reference/composite.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/render.hpp"

namespace mfr {

std::uint32_t PixelProbe::heldCount() const {
  std::uint32_t n = 0;
  for (const ProbeFragment& f : fragments) n += f.held ? 1u : 0u;
  return n;
}

namespace {

// The field value at each fragment of a field-coloured part: the ray through the pixel's centre
// meets its part's triangles (Möller–Trumbore, in double); the hit nearest the fragment's eye
// depth gives the barycentric weights for Mesh::scalars — or the point where a volume that colours
// the part is sampled (VolumeFieldSampler), as the renderers sample it.
void probeFieldValues(PixelProbe& probe, const Scene& scene, const Camera& camera) {
  const double aspect = static_cast<double>(probe.width) / probe.height;
  const glm::dmat4 view = camera.viewMatrix();
  const glm::dmat4 toWorld = glm::inverse(camera.projectionMatrix(aspect) * view);
  const glm::dvec2 ndc(2.0 * (probe.x + 0.5) / probe.width - 1.0, 1.0 - 2.0 * (probe.y + 0.5) / probe.height);
  const glm::dvec4 nearH = toWorld * glm::dvec4(ndc, -1.0, 1.0), farH = toWorld * glm::dvec4(ndc, 1.0, 1.0);
  const glm::dvec3 origin = glm::dvec3(nearH) / nearH.w, dir = glm::dvec3(farH) / farH.w - origin;
  for (ProbeFragment& f : probe.fragments) {
    const std::uint32_t id = f.fragment.objectId;
    if (id >= scene.objects.size()) continue;
    const Object& o = scene.objects[id];
    if (!o.material.fieldColors || !o.mesh || o.mesh->scalars.size() != o.mesh->positions.size()) continue;
    const Mesh& m = *o.mesh;
    const std::optional<VolumeFieldSampler> sampler = volumeFieldSampler(scene, o);  // at the hit, if a volume
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      glm::dvec3 p[3];
      for (int k = 0; k < 3; ++k)
        p[k] = glm::dvec3(o.transform *
                          glm::dvec4(glm::dvec3(m.positions[m.indices[t + static_cast<std::size_t>(k)]]), 1.0));
      const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0], q = glm::cross(dir, e2);
      const double det = glm::dot(e1, q);
      if (std::abs(det) < 1e-300) continue;
      const glm::dvec3 s = origin - p[0];
      const double u = glm::dot(s, q) / det;
      const glm::dvec3 r = glm::cross(s, e1);
      const double v = glm::dot(dir, r) / det;
      const double slack = 1e-9;  // a ray through an edge meets one of its triangles
      if (u < -slack || v < -slack || u + v > 1.0 + slack) continue;
      const glm::dvec3 hit = origin + (glm::dot(e2, r) / det) * dir;
      const double eyeDepth = -(view * glm::dvec4(hit, 1.0)).z;
      if (std::abs(eyeDepth - f.eyeDepth) >= best) continue;
      best = std::abs(eyeDepth - f.eyeDepth);
      const float w[3] = {static_cast<float>(1.0 - u - v), static_cast<float>(u), static_cast<float>(v)};
      f.value = 0.0f;
      if (sampler) {
        const double wd[3] = {1.0 - u - v, u, v};
        glm::dvec3 objectPoint(0.0);
        for (int k = 0; k < 3; ++k)
          objectPoint += wd[k] * glm::dvec3(m.positions[m.indices[t + static_cast<std::size_t>(k)]]);
        f.value = sampler->at(objectPoint);
      } else {
        for (int k = 0; k < 3; ++k) f.value += w[k] * m.scalars[m.indices[t + static_cast<std::size_t>(k)]];
      }
      f.hasValue = true;
    }
  }
}

}  // namespace

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
  probeFieldValues(probe, scene, camera);
  return probe;
}

void matchCapture(PixelProbe& probe, std::span<const Fragment> fragments, std::uint32_t count, double depthTolerance) {
  probe.captured = true;
  probe.methodCount = count;
  probe.methodFragments.assign(fragments.begin(), fragments.end());
  probe.unmatched = 0;
  for (ProbeFragment& f : probe.fragments) f.held = false;
  for (const Fragment& got : fragments) {
    ProbeFragment* best = nullptr;
    double bestDepth = std::numeric_limits<double>::infinity();
    int bestColour = 0;
    for (ProbeFragment& f : probe.fragments) {
      if (f.held) continue;
      const double d = std::abs(static_cast<double>(f.fragment.depth) - got.depth);
      if (d > rasterDepthTolerance(f.fragment, depthTolerance)) continue;
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
