// Exact operations on the oracle's sorted lists: front-to-back "over" compositing, image-space CSG
// (each pixel's visible fragment, csgVisibleFragment) and depth complexity (the per-pixel fragment
// count n(p) and its histogram).
#include "mfr/reference/composite.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/scene/section.hpp"
#include "number_text.hpp"

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
// ascending) and the integration state. Track: also each fragment's share of the colour (the
// probe), which needs each slab's fragments — several once the window is full and a newer one is
// merged into the newest slab.
template <bool Track>
struct ZThicknessState {
  struct Slab {
    float end = 0.0f;
    float sigma = 0.0f;
    glm::vec3 emission{0.0f};
    std::size_t members = 0;  // Track: index into fragmentsOf
  };
  std::array<Slab, MFR_ZTHICK_WINDOW> window{};
  std::size_t first = 0, count = 0;
  glm::vec3 colour{0.0f};
  float transmittance = 1.0f;
  float position = 0.0f;
  std::vector<std::vector<std::pair<std::size_t, float>>> fragmentsOf;  // Track: (fragment, σ) per slab
  std::vector<double> weights;                                          // Track: per fragment

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
      if constexpr (Track) {
        // Each fragment absorbs (and so emits) its σ's part of what the stretch absorbs.
        const double share = static_cast<double>(transmittance) * absorbed / sigma;
        for (std::size_t i = 0; i < count; ++i)
          for (const auto& [fragment, fragmentSigma] : fragmentsOf[slab(i).members])
            weights[fragment] += share * fragmentSigma;
      }
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

  void run(std::span<const Fragment> sorted, const glm::vec4& depthToEye, float thickness) {
    if constexpr (Track) weights.assign(sorted.size(), 0.0);
    for (std::size_t index = 0; index < sorted.size(); ++index) {
      const Fragment& f = sorted[index];
      const glm::vec4 c = glm::unpackUnorm4x8(f.color);
      const float alpha = std::min(c.a, static_cast<float>(MFR_ZTHICK_MAX_ALPHA));
      if (alpha <= 0.0f) continue;
      const float ndc = 2.0f * f.depth - 1.0f;
      const float z = -(depthToEye.x * ndc + depthToEye.y) / (depthToEye.z * ndc + depthToEye.w);
      closeUntil(z);
      if (count == 0) position = z;
      integrate(z);
      const float sigma = -std::log(1.0f - alpha) / thickness;
      if (count == window.size()) {
        Slab& newest = slab(count - 1);
        newest.sigma += sigma;
        newest.emission += sigma * glm::vec3(c);
        if constexpr (Track) fragmentsOf[newest.members].emplace_back(index, sigma);
        continue;
      }
      slab(count) = {z + thickness, sigma, sigma * glm::vec3(c), fragmentsOf.size()};
      if constexpr (Track) fragmentsOf.push_back({{index, sigma}});
      ++count;
    }
    closeUntil(std::numeric_limits<float>::max());
  }
};

}  // namespace

glm::vec3 compositeZThickness(std::span<const Fragment> sorted, const glm::vec4& depthToEye, float thickness,
                              const glm::vec3& background) {
  ZThicknessState<false> s;
  s.run(sorted, depthToEye, thickness);
  return s.colour + s.transmittance * background;
}

ZThicknessBreakdown compositeZThicknessBreakdown(std::span<const Fragment> sorted, const glm::vec4& depthToEye,
                                                 float thickness, const glm::vec3& background) {
  ZThicknessState<true> s;
  s.run(sorted, depthToEye, thickness);
  return {s.colour + s.transmittance * background, std::move(s.weights), s.transmittance};
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
    throw Error("--thickness", "must be a positive length in scene units (got " + numberText(thickness) + ")");
  const glm::vec4 toEye(camera.depthToEye());
  ImageRGBA8 image(lists.width, lists.height);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x)
      store(image, x, y, compositeZThickness(lists.pixel(x, y), toEye, static_cast<float>(thickness), background));
  return image;
}

VolumeRaySetup volumeRaySetup(std::span<const Volume> volumes, const Camera& camera, int width, int height, double step,
                              const std::optional<Bounds>& clip, const std::optional<SectionPlane>& section) {
  if (volumes.empty()) throw Error("operation volume", "no volume to draw");
  if (volumes.size() > MFR_MAX_VOLUMES)
    throw Error("operation volume", std::to_string(volumes.size()) + " volumes: at most " +
                                        std::to_string(MFR_MAX_VOLUMES) + " can be drawn at once");
  VolumeRaySetup s;
  // Every position of the march is relative to the volumes' centre, composed in double: in world
  // floats a volume 1e6 from the origin lost its detail (RMSE 0.0086 against the same march in
  // double; 0.32 at 1e8; a bug hunt). Both renderers march with this setup, so they still agree.
  Bounds all;
  for (const Volume& volume : volumes) {
    const Bounds b = volume.bounds();
    if (b.valid()) {
      all.extend(b.min);
      all.extend(b.max);
    }
  }
  s.origin = all.valid() ? all.center() : glm::dvec3(0.0);
  if (!(std::isfinite(s.origin.x) && std::isfinite(s.origin.y) && std::isfinite(s.origin.z)))
    s.origin = glm::dvec3(0.0);
  const glm::dmat4 fromRelative = glm::translate(glm::dmat4(1.0), s.origin);
  const double aspect = static_cast<double>(width) / height;
  s.invViewProj = glm::mat4(glm::inverse(camera.projectionMatrix(aspect) * camera.viewMatrix() * fromRelative));
  s.viewport = glm::vec2(static_cast<float>(width), static_cast<float>(height));
  double defaultStep = volumes.front().defaultStep();
  for (const Volume& volume : volumes) {
    VolumeMedium m;
    m.grid = volume.grid;
    m.worldToGrid = glm::mat4(glm::inverse(volume.gridToWorld()) * fromRelative);
    m.dims = volume.grid->dims;
    m.tfLow = static_cast<float>(volume.transfer.low());
    m.tfHigh = static_cast<float>(volume.transfer.high());
    m.table = volume.transfer.table();
    m.shading = volume.shading;
    s.media.push_back(std::move(m));
    defaultStep = std::min(defaultStep, volume.defaultStep());
  }
  s.step = static_cast<float>(step > 0.0 ? step : defaultStep);
  if (clip) {
    s.clip = true;
    s.clipMin = glm::vec3(clip->min - s.origin);
    s.clipMax = glm::vec3(clip->max - s.origin);
  }
  if (section) {
    s.section = true;
    // dot(n, p) + d with p = r + origin: dot(n, r) + (dot(n, origin) + d).
    const glm::dvec4 plane = sectionPlaneEquation(*section);
    s.sectionPlane = glm::vec4(glm::dvec4(glm::dvec3(plane), plane.w + glm::dot(glm::dvec3(plane), s.origin)));
  }
  return s;
}

static_assert(Scene::kMaxVisibleVolumes == MFR_MAX_VOLUMES);

namespace {

// The per-pixel state of shaders/ops/volume.glsl, step for step.
struct VolumeMarcher {
  const VolumeRaySetup& setup;
  glm::vec3 color{0.0f};
  float transmittance = 1.0f;
  glm::vec2 ndc{0.0f};
  glm::vec3 rayStart{0.0f}, rayDir{0.0f};
  std::array<glm::vec3, MFR_MAX_VOLUMES> gridStart{}, gridDir{};
  std::array<float, MFR_MAX_VOLUMES> enter{}, exit{};  // each volume's part of the ray (empty: enter == exit)
  float tEnter = 0.0f, tExit = 0.0f, step = 0.0f, t = 0.0f;
  int next = 1;
  // Optional (the probe): each medium's share of the light absorbed so far, T·absorbed·σ_i/σ summed.
  std::vector<float>* absorbedByVolume = nullptr;

  [[nodiscard]] int count() const { return static_cast<int>(setup.media.size()); }

  [[nodiscard]] glm::vec3 unproject(float ndcZ) const {
    const glm::vec4 p = setup.invViewProj * glm::vec4(ndc, ndcZ, 1.0f);
    return glm::vec3(p) / p.w;
  }

  // a / b with both scaled by 2^-32 (exactly) where |b| > 2^100, as the shader does (volumeDivide:
  // GPU division is accurate only for divisors up to 2^126).
  [[nodiscard]] static float divide(float a, float b) {
    const float s = std::abs(b) > 0x1p100f ? 0x1p-32f : 1.0f;
    return (a * s) / (b * s);
  }

  [[nodiscard]] glm::vec4 transfer(const VolumeMedium& m, float v) const {
    // Halved first, exactly: v − low overflows a float for values beyond ±1.7e38 (a file's
    // ±FLT_MAX "no data" marks). A NaN position (a table of one value) is the first entry.
    const float along = divide(0.5f * v - 0.5f * m.tfLow, 0.5f * m.tfHigh - 0.5f * m.tfLow);
    const float u = (along > 0.0f ? std::min(along, 1.0f) : 0.0f) * static_cast<float>(MFR_VOLUME_TF_SIZE - 1);
    const int i = std::min(static_cast<int>(u), MFR_VOLUME_TF_SIZE - 2);
    const float f = u - static_cast<float>(i);
    return glm::mix(m.table[static_cast<std::size_t>(i)], m.table[static_cast<std::size_t>(i) + 1], f);
  }

  // The emission factor of a shaded volume at grid point g (shaders/ops/volume.glsl volumeShade).
  [[nodiscard]] float shade(const VolumeMedium& m, const glm::vec3& g) const {
    const VolumeGrid& grid = *m.grid;
    // Central differences, halved before subtracting and measured in units of the largest
    // component, so that no step overflows a float (values near ±FLT_MAX; transfer above).
    const auto half = [&](const glm::vec3& d) { return 0.5f * grid.sample(g + d) - 0.5f * grid.sample(g - d); };
    const glm::vec3 gradient(half({1.0f, 0.0f, 0.0f}), half({0.0f, 1.0f, 0.0f}), half({0.0f, 0.0f, 1.0f}));
    const float largest = std::max({std::abs(gradient.x), std::abs(gradient.y), std::abs(gradient.z)});
    if (!(largest > 0.0f)) return 1.0f;
    const glm::vec3 unit(divide(gradient.x, largest), divide(gradient.y, largest), divide(gradient.z, largest));
    const float perCell = glm::length(unit);  // |∇| / largest, in [1, √3]
    // ∇ in world units: the transpose of world → grid's linear part applied to ∇ in grid units.
    const glm::vec3 world = glm::transpose(glm::mat3(m.worldToGrid)) * unit;
    const float facing = std::abs(glm::dot(world, rayDir)) / glm::length(world);
    const float lit = static_cast<float>(MFR_VOLUME_AMBIENT) + static_cast<float>(MFR_VOLUME_DIFFUSE) * facing;
    // |∇| / (|∇| + edge · (high − low)), both terms divided by `largest`.
    const float range = 2.0f * divide(0.5f * m.tfHigh - 0.5f * m.tfLow, largest);
    const float w = perCell / (perCell + static_cast<float>(MFR_VOLUME_SHADE_EDGE) * range);
    return glm::mix(1.0f, lit, w);
  }

  void begin(int glX, int glY) {
    ndc = (glm::vec2(static_cast<float>(glX), static_cast<float>(glY)) + 0.5f) / setup.viewport * 2.0f - 1.0f;
    rayStart = unproject(-1.0f);
    const glm::vec3 rayEnd = unproject(1.0f);
    const float rayLength = glm::distance(rayEnd, rayStart);
    rayDir = (rayEnd - rayStart) / rayLength;
    // The part of the ray every volume shares: inside the clip box and on the kept side of the plane.
    float c0 = 0.0f, c1 = rayLength;
    if (setup.clip)  // slabs of the clip box, in world space
      for (int a = 0; a < 3; ++a) {
        if (std::abs(rayDir[a]) < 1e-30f) {
          if (rayStart[a] < setup.clipMin[a] || rayStart[a] > setup.clipMax[a]) c1 = -1.0f;
        } else {
          const float ta = (setup.clipMin[a] - rayStart[a]) / rayDir[a];
          const float tb = (setup.clipMax[a] - rayStart[a]) / rayDir[a];
          c0 = std::max(c0, std::min(ta, tb));
          c1 = std::min(c1, std::max(ta, tb));
        }
      }
    if (setup.section) {  // the kept half-space of the section plane
      const glm::vec3 n(setup.sectionPlane);
      const float s0 = glm::dot(n, rayStart) + setup.sectionPlane.w, ds = glm::dot(n, rayDir);
      if (std::abs(ds) < 1e-30f) {
        if (s0 < 0.0f) c1 = -1.0f;
      } else if (ds > 0.0f) {
        c0 = std::max(c0, -s0 / ds);
      } else {
        c1 = std::min(c1, -s0 / ds);
      }
    }
    bool any = false;
    for (int i = 0; i < count(); ++i) {
      const VolumeMedium& m = setup.media[static_cast<std::size_t>(i)];
      gridStart[i] = glm::vec3(m.worldToGrid * glm::vec4(rayStart, 1.0f));
      gridDir[i] = glm::vec3(m.worldToGrid * glm::vec4(rayDir, 0.0f));
      float t0 = c0, t1 = c1;
      const glm::vec3 last = glm::vec3(m.dims - 1);
      for (int a = 0; a < 3; ++a) {  // slabs of the box [0, dims - 1]
        if (std::abs(gridDir[i][a]) < 1e-30f) {
          if (gridStart[i][a] < 0.0f || gridStart[i][a] > last[a]) t1 = -1.0f;
        } else {
          const float ta = (0.0f - gridStart[i][a]) / gridDir[i][a];
          const float tb = (last[a] - gridStart[i][a]) / gridDir[i][a];
          t0 = std::max(t0, std::min(ta, tb));
          t1 = std::min(t1, std::max(ta, tb));
        }
      }
      enter[i] = t0;
      exit[i] = std::max(t1, t0);
      if (exit[i] > enter[i]) {
        tEnter = any ? std::min(tEnter, enter[i]) : enter[i];
        tExit = any ? std::max(tExit, exit[i]) : exit[i];
        any = true;
      }
    }
    if (!any) tEnter = tExit = c0 > 0.0f ? c0 : 0.0f;
    step = std::max(setup.step, (tExit - tEnter) / static_cast<float>(MFR_VOLUME_MAX_STEPS));
    t = tEnter;
    next = 1;
  }

  void march(float tTo) {
    tTo = std::min(tTo, tExit);
    for (int it = 0; it < MFR_VOLUME_MAX_STEPS + 2 + 2 * MFR_MAX_VOLUMES && t < tTo &&
                     transmittance >= static_cast<float>(MFR_VOLUME_MIN_TRANSMITTANCE);
         ++it) {
      const float boundary = tEnter + static_cast<float>(next) * step;
      float end = std::min(boundary, tTo);
      for (int i = 0; i < count(); ++i) {  // a box's entry or exit cuts the interval too
        if (enter[i] > t && enter[i] < end) end = enter[i];
        if (exit[i] > t && exit[i] < end) end = exit[i];
      }
      if (end > t) {
        const float mid = 0.5f * (t + end);
        float sigma = 0.0f;
        glm::vec3 emission(0.0f);
        std::array<float, MFR_MAX_VOLUMES> sigmaOf{};
        for (int i = 0; i < count(); ++i) {
          if (!(mid > enter[i] && mid < exit[i])) continue;
          const VolumeMedium& m = setup.media[static_cast<std::size_t>(i)];
          const glm::vec3 g = gridStart[i] + gridDir[i] * mid;
          const glm::vec4 c = transfer(m, m.grid->sample(g));
          if (c.a > 0.0f) {
            sigma += c.a;
            emission += c.a * glm::vec3(c) * (m.shading ? shade(m, g) : 1.0f);
            sigmaOf[static_cast<std::size_t>(i)] = c.a;
          }
        }
        if (sigma > 0.0f) {
          const float absorbed = 1.0f - std::exp(-sigma * (end - t));
          if (absorbedByVolume)
            for (int i = 0; i < count(); ++i)
              (*absorbedByVolume)[static_cast<std::size_t>(i)] +=
                  transmittance * absorbed * sigmaOf[static_cast<std::size_t>(i)] / sigma;
          color += transmittance * absorbed * (emission / sigma);
          transmittance *= 1.0f - absorbed;
        }
        t = end;
      }
      if (end >= boundary) ++next;
    }
  }

  // The ray parameter of a fragment's surface.
  [[nodiscard]] float tDepth(const Fragment& f) const {
    return glm::dot(unproject(2.0f * f.depth - 1.0f) - rayStart, rayDir);
  }

  void surface(const glm::vec4& c) {
    color += transmittance * c.a * glm::vec3(c);
    transmittance *= 1.0f - c.a;
  }

  void fragment(const Fragment& f) {
    march(tDepth(f));
    surface(glm::unpackUnorm4x8(f.color));
  }
};

}  // namespace

glm::vec3 compositeVolume(std::span<const Fragment> sorted, int glX, int glY, const VolumeRaySetup& setup,
                          const glm::vec3& background) {
  VolumeMarcher m{setup};
  m.begin(glX, glY);
  for (const Fragment& f : sorted) m.fragment(f);
  m.march(m.tExit);
  return m.color + m.transmittance * background;
}

VolumeBreakdown compositeVolumeBreakdown(std::span<const Fragment> sorted, int glX, int glY,
                                         const VolumeRaySetup& setup, const glm::vec3& background) {
  VolumeMarcher m{setup};
  m.begin(glX, glY);
  VolumeBreakdown out;
  std::vector<float> byVolume(setup.media.size(), 0.0f);
  m.absorbedByVolume = &byVolume;
  // The same steps as compositeVolume, with the medium marched apart from each surface.
  const auto medium = [&](float tTo) {
    const glm::vec3 before = m.color;
    const float in = m.transmittance;
    std::fill(byVolume.begin(), byVolume.end(), 0.0f);
    m.march(tTo);
    out.mediumColor.push_back(m.color - before);
    out.mediumWeight.push_back(in - m.transmittance);
    out.mediumWeightByVolume.push_back(byVolume);
  };
  for (const Fragment& f : sorted) {
    medium(m.tDepth(f));
    const glm::vec4 c = glm::unpackUnorm4x8(f.color);
    out.surfaceWeight.push_back(m.transmittance * c.a);
    m.surface(c);
  }
  medium(m.tExit);
  out.backgroundWeight = m.transmittance;
  out.color = m.color + m.transmittance * background;
  return out;
}

ImageRGBA8 compositeVolume(const FragmentLists& lists, const Camera& camera, std::span<const Volume> volumes,
                           double step, const glm::vec3& background, const std::optional<Bounds>& clip,
                           const std::optional<SectionPlane>& section) {
  for (const Volume& volume : volumes) volume.validate();
  if (!std::isfinite(step) || step < 0.0)
    throw Error("--step", "must be a positive length in scene units (got " + numberText(step) + ")");
  const VolumeRaySetup setup = volumeRaySetup(volumes, camera, lists.width, lists.height, step, clip, section);
  ImageRGBA8 image(lists.width, lists.height);
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x)
      store(image, x, y, compositeVolume(lists.pixel(x, y), x, lists.height - 1 - y, setup, background));
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
