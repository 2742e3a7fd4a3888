#pragma once
// Scalar volumes: a dense grid of point samples placed in the world (VTK image-data convention:
// grid point (i, j, k) sits at origin + (i, j, k)·spacing in object space, the domain is the box
// between the first and the last point), and the transfer function that turns a scalar into an
// emission colour and an extinction coefficient. The operation "volume" ray-marches it between
// each pixel's sorted surface fragments (shaders/ops/volume.glsl, reference/composite.hpp).
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/mesh.hpp"

namespace mfr {

// The scalar samples, shared between copies of a scene (volumes are large).
struct VolumeGrid {
  // Limits checked by validate() and by the loaders before they allocate: one GL 3D texture holds
  // the grid (2048 per side is what GL 4.5 guarantees), and at most 2^30 points (4 GiB of floats).
  static constexpr int kMaxPointsPerAxis = 2048;
  static constexpr std::size_t kMaxPoints = std::size_t{1} << 30;

  glm::ivec3 dims{0};         // points per axis, each ≥ 2
  std::vector<float> values;  // dims.x·dims.y·dims.z, x fastest, then y, then z

  [[nodiscard]] float at(int i, int j, int k) const {
    return values[(static_cast<std::size_t>(k) * static_cast<std::size_t>(dims.y) + static_cast<std::size_t>(j)) *
                      static_cast<std::size_t>(dims.x) +
                  static_cast<std::size_t>(i)];
  }
  // Trilinear interpolation at grid coordinates g (point (i,j,k) at g = (i,j,k)), clamped to the
  // grid; the same arithmetic as shaders/ops/volume.glsl.
  [[nodiscard]] float sample(const glm::vec3& g) const;
  // Smallest and largest finite value.
  [[nodiscard]] glm::vec2 range() const;
  // Throws mfr::Error(what, reason) for dims below 2, a size mismatch or a non-finite value.
  void validate(const std::string& what) const;
};

// One control point of a transfer function: at scalar `value`, display colour rgb and opacity a,
// the fraction of light a slab of TransferFunction::unitDistance absorbs.
struct TransferPoint {
  double value = 0.0;
  glm::vec4 color{1.0f};
};

// Piecewise-linear colour and opacity over scalar values (clamped outside the first and last
// point), like ParaView's colour and opacity maps with its "scalar opacity unit distance".
struct TransferFunction {
  std::vector<TransferPoint> points;  // ascending values, at least two
  double unitDistance = 1.0;          // world length over which opacity a absorbs a (> 0)

  // The table both renderers sample: MFR_VOLUME_TF_SIZE entries (rgb, σ) evenly spaced from the
  // first point's value to the last one's, σ = -ln(1 - min(a, MFR_VOLUME_MAX_ALPHA))/unitDistance
  // the extinction per world unit; a scalar s between entries interpolates (rgb, σ) linearly.
  [[nodiscard]] std::vector<glm::vec4> table() const;
  [[nodiscard]] double low() const { return points.front().value; }
  [[nodiscard]] double high() const { return points.back().value; }
  // Throws mfr::Error(what, reason): fewer than two points, values not ascending or equal ends,
  // colours outside [0, 1], a non-positive or non-finite unit distance.
  void validate(const std::string& what) const;
};

// Named transfer functions over [low, high]: "grayscale" (black → white, opacity ramp),
// "bone" (CT: soft tissue faint and warm, bone white and dense), "fire", "cool-warm". Throws
// mfr::Error("transfer function", …) for an unknown name (listing the known ones).
TransferFunction transferPreset(const std::string& name, double low, double high, double unitDistance);
const std::vector<std::string>& transferPresetNames();

// The transfer function a volume file gets when nothing else is said: preset "grayscale" over the
// grid's range() (an empty range widened by 1), unit distance the diagonal of worldBounds / 50
// (1 when the bounds are not valid).
TransferFunction defaultTransfer(const VolumeGrid& grid, const Bounds& worldBounds);

struct Volume {
  std::string name;
  std::shared_ptr<const VolumeGrid> grid;
  glm::dvec3 origin{0.0};     // object-space position of grid point (0, 0, 0)
  glm::dvec3 spacing{1.0};    // object-space distance between grid points per axis (> 0)
  glm::dmat4 transform{1.0};  // object → world
  TransferFunction transfer;
  bool visible = true;
  // Gradient shading with a headlight (MFR_VOLUME_AMBIENT/DIFFUSE in shaders/common/bindings.h):
  // boundaries inside the medium read as surfaces. Off: pure emission-absorption.
  bool shading = false;
  // The named field the samples came from — a VTK point-data array or an OpenVDB grid — and every
  // field of the file that could have been read instead, in file order. Both empty for formats
  // with one unnamed field (INRIMAGE, MetaImage, NRRD, InVesalius).
  std::string field;
  std::vector<std::string> fields;
  // The file it was read from (empty: made in memory), and the part of `transform` a scene put on
  // top of the file's own placement — so that another field of the file can be read in its place
  // (a .vdb file's grids each have a box and transform of their own).
  std::filesystem::path file;
  glm::dmat4 sceneTransform{1.0};

  // Object → grid coordinates composed with transform: world → grid is inverse(gridToWorld()).
  [[nodiscard]] glm::dmat4 gridToWorld() const;
  [[nodiscard]] Bounds bounds() const;  // world bounds of the domain box
  // The default ray-march step: half the smallest world-space distance between grid points.
  [[nodiscard]] double defaultStep() const;
  // Throws mfr::Error(name, reason) for a bad grid, spacing, transform or transfer function.
  void validate() const;
};

}  // namespace mfr
