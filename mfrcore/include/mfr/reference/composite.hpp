#pragma once
// Exact operations on the oracle's sorted lists.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/image.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/csg.hpp"
#include "mfr/scene/scene.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr {

// Front-to-back "over": C = Σ_i c_i α_i Π_{j<i}(1-α_j) + (Π_j (1-α_j))·background, in float,
// on the stored (display) values; result rounded to 8 bits, alpha 255.
glm::vec3 compositeOver(std::span<const Fragment> sorted, const glm::vec3& background);
ImageRGBA8 compositeOver(const FragmentLists& lists, const glm::vec3& background);

// Z-thickness blending (Kim & Kye, CGF 40(7) 2021; shaders/ops/zthickness.glsl is the same
// definition, in the same float arithmetic): each fragment is a slab of `thickness` (world units
// along the view axis) behind its surface, extinction σ = -ln(1 - α)/thickness with α clamped to
// MFR_ZTHICK_MAX_ALPHA, emission σ·rgb; the piecewise-constant medium is integrated exactly
// front to back, then the background. Slabs further apart than the thickness give "over"; overlapping
// slabs blend order-independently. At most MFR_ZTHICK_WINDOW slabs are open at once (a newer one
// is merged into the newest open slab). depthToEye: Camera::depthToEye().
glm::vec3 compositeZThickness(std::span<const Fragment> sorted, const glm::vec4& depthToEye, float thickness,
                              const glm::vec3& background);
// The same colour taken apart (the pixel probe): weights[i] is fragment i's share of it — over
// every stretch where its slab is open, the light reaching the stretch times the part of what the
// stretch absorbs that its own extinction takes (σᵢ/σ) — so that colour = Σ weights[i]·rgbᵢ +
// transmittance·background (to float rounding). A fragment with no opacity has weight 0.
struct ZThicknessBreakdown {
  glm::vec3 color{0.0f};        // compositeZThickness's, in the same arithmetic
  std::vector<double> weights;  // per fragment of `sorted`
  double transmittance = 1.0;   // the background's share
};
ZThicknessBreakdown compositeZThicknessBreakdown(std::span<const Fragment> sorted, const glm::vec4& depthToEye,
                                                 float thickness, const glm::vec3& background);
// The image; throws mfr::Error("--thickness", …) unless thickness is finite and > 0.
ImageRGBA8 compositeZThickness(const FragmentLists& lists, const Camera& camera, double thickness,
                               const glm::vec3& background);

// Operation "volume" (shaders/ops/volume.glsl is the same definition, in the same float arithmetic):
// the visible volumes' emission-absorption integral ray-marched between the pixel's sorted surface
// fragments, each surface composited with "over" at its exact depth. The ray of a pixel runs from
// its centre on the near plane to the far plane (t in world units). From the first point where it
// enters a volume's box to the last where it leaves one, interval boundaries lie every `step`, cut
// further at surfaces and wherever the ray enters or leaves a box; each interval takes, for every
// volume whose box holds it, the (rgb_i, σ_i) of that volume's transfer table at the midpoint's
// trilinear sample. Where volumes overlap (Kainz et al. 2009's multiple volumes) their media mix as
// emission-absorption media do (Max 1995): σ = Σσ_i, the emitted colour Σσ_i·rgb_i·shade_i / σ, so
// C += T·(1 - e^(-σ·Δ))·Σσ_i·rgb_i·shade_i/σ, T ·= e^(-σ·Δ), shade_i = 1 unless volume i is shaded
// (MFR_VOLUME_AMBIENT in shaders/common/bindings.h says how). Marching stops once T < MFR_VOLUME_MIN_TRANSMITTANCE;
// a chord longer than MFR_VOLUME_MAX_STEPS steps gets a longer step.
struct VolumeMedium {
  std::shared_ptr<const VolumeGrid> grid;
  glm::mat4 worldToGrid{1.0f};
  glm::ivec3 dims{0};
  float tfLow = 0.0f, tfHigh = 1.0f;
  std::vector<glm::vec4> table;  // TransferFunction::table()
  bool shading = false;          // Volume::shading
};
// Positions ("world" below) are relative to `origin`, the drawn volumes' centre: NDC, the grids,
// the clip box and the section plane are all mapped to those coordinates in double, then rounded.
struct VolumeRaySetup {
  glm::dvec3 origin{0.0};       // world position of the march's coordinate origin
  glm::mat4 invViewProj{1.0f};  // NDC → world − origin (computed in double, rounded to float)
  glm::vec2 viewport{0.0f};
  float step = 0.0f;                // world units
  std::vector<VolumeMedium> media;  // 1 … MFR_MAX_VOLUMES
  // Scene::clipBox: the march is limited to the part of the ray inside it too (world space).
  bool clip = false;
  glm::vec3 clipMin{0.0f};
  glm::vec3 clipMax{0.0f};
  // Scene::section: the march is limited to dot(plane.xyz, p) + plane.w >= 0 too (world space).
  bool section = false;
  glm::vec4 sectionPlane{0.0f};
};
// The values both renderers use; step ≤ 0 picks the smallest Volume::defaultStep(); clip: the
// scene's clip box; section: its section plane. Throws mfr::Error for no volume or more than
// MFR_MAX_VOLUMES.
VolumeRaySetup volumeRaySetup(std::span<const Volume> volumes, const Camera& camera, int width, int height, double step,
                              const std::optional<Bounds>& clip = std::nullopt,
                              const std::optional<SectionPlane>& section = std::nullopt);
inline VolumeRaySetup volumeRaySetup(const Volume& volume, const Camera& camera, int width, int height, double step,
                                     const std::optional<Bounds>& clip = std::nullopt,
                                     const std::optional<SectionPlane>& section = std::nullopt) {
  return volumeRaySetup(std::span<const Volume>(&volume, 1), camera, width, height, step, clip, section);
}
// One pixel; (glX, glY) in GL window coordinates (row 0 at the bottom).
glm::vec3 compositeVolume(std::span<const Fragment> sorted, int glX, int glY, const VolumeRaySetup& setup,
                          const glm::vec3& background);
// The same pixel taken apart (the probe): each surface's share of the colour, α·T with T the
// transmittance in front of it through surfaces and medium, and for the stretch of medium in front
// of each surface and behind the last (n + 1 stretches) the colour it adds and its share,
// T_in·(1 − its own transmittance), also split by volume (each interval's absorbed share divided
// in proportion to σ_i). The shares and the background's add up to 1.
struct VolumeBreakdown {
  std::vector<float> surfaceWeight;                      // per fragment
  std::vector<glm::vec3> mediumColor;                    // n + 1: added to the pixel (already weighted)
  std::vector<float> mediumWeight;                       // n + 1
  std::vector<std::vector<float>> mediumWeightByVolume;  // n + 1, each one per medium of the setup
  glm::vec3 color{0.0f};                                 // = compositeVolume
  float backgroundWeight = 1.0f;
};
VolumeBreakdown compositeVolumeBreakdown(std::span<const Fragment> sorted, int glX, int glY,
                                         const VolumeRaySetup& setup, const glm::vec3& background);
// The image of the given volumes (Scene::visibleVolumes()).
ImageRGBA8 compositeVolume(const FragmentLists& lists, const Camera& camera, std::span<const Volume> volumes,
                           double step, const glm::vec3& background, const std::optional<Bounds>& clip = std::nullopt,
                           const std::optional<SectionPlane>& section = std::nullopt);
inline ImageRGBA8 compositeVolume(const FragmentLists& lists, const Camera& camera, const Volume& volume, double step,
                                  const glm::vec3& background, const std::optional<Bounds>& clip = std::nullopt,
                                  const std::optional<SectionPlane>& section = std::nullopt) {
  return compositeVolume(lists, camera, std::span<const Volume>(&volume, 1), step, background, clip, section);
}

// Image-space CSG (scene.csg, rule of csgVisibleFragment with the scene's mirrored primitives):
// each pixel shows its visible fragment's colour as an opaque surface (RGB of the stored colour,
// its opacity ignored: solids), the scene's background where there is none; rounded to 8 bits,
// alpha 255. The lists must be the oracle's for this scene. Throws mfr::Error when the scene has
// no CSG tree.
ImageRGBA8 compositeCsg(const FragmentLists& lists, const Scene& scene);

// Depth complexity n(p) per pixel (as a 1-channel float image) and its histogram:
// histogram[n] = number of pixels with exactly n fragments (size maxCount+1).
ImageF depthComplexity(const FragmentLists& lists);
std::vector<std::uint64_t> depthComplexityHistogram(const FragmentLists& lists);

}  // namespace mfr
