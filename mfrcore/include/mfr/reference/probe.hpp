#pragma once
// The pixel probe: what lies behind one pixel. The oracle's exact sorted list of the pixel, each
// fragment with its part, its distance from the eye and its share of the "over" result, and —
// given a GPU method's capture of the same pixel (GpuRenderer::capture with a one-pixel region) —
// which of those fragments the method holds. `mfr probe` prints it; mfrview's Probe dock shows it.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/reference/oracle.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

struct RenderRequest;

struct ProbeFragment {
  Fragment fragment;              // as the oracle casts it (window depth, shaded colour, object, facing)
  double eyeDepth = 0.0;          // distance along the view axis (world units), Camera::depthToEye
  double weight = 0.0;            // α_i·Π_{j<i}(1 − α_j): the fraction of the pixel's colour it gives
  bool held = false;              // the method's capture holds it (matchCapture)
  double hybridWeight = 0.0;      // its share of the hybrid colour under the method's core/tail split (splitHybrid)
  double volumeWeight = 0.0;      // its share of the "volume" colour: α·T through surfaces and medium (splitVolume)
  double zthicknessWeight = 0.0;  // its share of the "zthickness" colour, blended with the slabs it overlaps
  // Its part coloured by a field (Material::fieldColors): the field's value where the pixel's ray
  // meets the surface, as the colour was made (Mesh::scalars interpolated at the hit; a volume's
  // value sampled there, VolumeFieldSampler).
  bool hasValue = false;
  float value = 0.0f;
};

// A stretch of the volumes' medium along the pixel's ray (splitVolume).
struct ProbeMedium {
  glm::vec3 color{0.0f};               // what it adds to the pixel's colour
  double weight = 0.0;                 // its share of the colour: the light reaching it times what it absorbs
  std::vector<double> weightByVolume;  // weight split by volume (PixelProbe::volumeNames), σ_i/σ per step
};

struct PixelProbe {
  int x = 0;  // image coordinates, y = 0 is the top row
  int y = 0;
  int width = 0;  // of the image the pixel belongs to
  int height = 0;
  bool edge = false;                     // the centre lies on a projected triangle edge: rasterisation may differ
  bool depthTie = false;                 // two fragments at one depth: their order is undefined
  std::vector<ProbeFragment> fragments;  // front to back
  glm::vec3 exactColor{0.0f};            // "over" of every fragment on the background
  double transmittance = 1.0;            // Π(1 − α): the background's share

  // Set by matchCapture.
  bool captured = false;
  std::uint32_t methodCount = 0;          // fragments the method holds at the pixel
  std::vector<Fragment> methodFragments;  // its sorted list as read back (at most what was kept)
  std::uint32_t unmatched = 0;            // of methodFragments, those at no oracle fragment's depth
  [[nodiscard]] std::uint32_t heldCount() const;

  // Set by splitHybrid.
  bool hybrid = false;
  glm::vec3 hybridColor{0.0f};    // core by "over", tail by its weighted average, on the background
  double hybridBackground = 0.0;  // the background's share: τ_core·τ_tail

  // Set by splitVolume.
  bool volume = false;
  std::vector<ProbeMedium> medium;       // fragments.size() + 1: in front of fragment i; the last behind them all
  std::vector<std::string> volumeNames;  // the volumes drawn, in the order of weightByVolume
  glm::vec3 volumeColor{0.0f};           // the exact colour under the operation "volume"
  double volumeBackground = 0.0;

  // Set by splitZThickness.
  bool zthickness = false;
  double thickness = 0.0;             // the slab thickness used (world units)
  glm::vec3 zthicknessColor{0.0f};    // the exact colour under the operation "zthickness"
  double zthicknessBackground = 0.0;  // the background's share
  std::size_t zthicknessBlended = 0;  // surfaces within the thickness of a neighbour (they blend)
};

// The probe of pixel (x, y) of a width × height image (throws mfr::Error for a pixel outside it,
// an empty scene or a bad camera, like castFragments). Casts only that pixel; the field value of
// every fragment of a field-coloured part comes from the triangle of its part that the pixel's ray
// meets at the fragment's depth.
PixelProbe probePixel(const Scene& scene, const Camera& camera, int width, int height, int x, int y,
                      const OracleOptions& options = {});

// Marks the oracle fragments a method holds: each captured fragment is paired with the unpaired
// oracle fragment nearest in depth within rasterDepthTolerance(oracle fragment, depthTolerance)
// (window depth: `depthTolerance` relative above 1 plus the subpixel-snap term — the tolerance of
// the GPU-versus-oracle tests), the closer colour deciding between equal depths.
// `count` is what the method reports holding (it may exceed fragments.size() when the read-back
// kept fewer).
void matchCapture(PixelProbe& probe, std::span<const Fragment> fragments, std::uint32_t count,
                  double depthTolerance = 1e-5);

// Hybrid transparency with the method's own split (after matchCapture; reference/hybrid.hpp): the
// fragments it holds are the core, composited by "over" in depth order; the others are the tail,
// replaced behind the core by their α-weighted average with transmittance (1 − α_avg)^t. Sets each
// fragment's hybridWeight — a core fragment's α·Π(1 − α) over the core in front of it, a tail
// fragment's τ_core·(α_i / Σα_tail)·(1 − τ_tail) — the background's share and the colour: what a
// method resolving with the operation "hybrid" (the budget methods, a k-buffer with its tail) draws
// at the pixel, and so what the budget costs there against exactColor.
void splitHybrid(PixelProbe& probe, glm::vec3 background);

// The operation "volume" at the probed pixel (reference/composite.hpp compositeVolumeBreakdown, on
// the probe's exact list): each surface's share and the medium's before, between and behind them,
// and the exact colour — the scene's visible volumes as `request` draws them (step, shading), cropped
// by the scene's clip box and section; each stretch also split by volume. Throws mfr::Error when
// the scene has no visible volume.
void splitVolume(PixelProbe& probe, const Scene& scene, const Camera& camera, const RenderRequest& request);

// The operation "zthickness" at the probed pixel (reference/composite.hpp
// compositeZThicknessBreakdown on the probe's exact list, with the thickness `request` asks for —
// zThicknessOf: 1 % of the scene's diagonal by default): each surface's share of the blended
// colour, where surfaces closer than the thickness blend instead of covering each other.
void splitZThickness(PixelProbe& probe, const Scene& scene, const Camera& camera, const RenderRequest& request);

}  // namespace mfr
