#include "mfr/scene/volume.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "number_text.hpp"

namespace mfr {

float VolumeGrid::sample(const glm::vec3& g) const {
  // Same steps as volumeSample() in shaders/ops/volume.glsl.
  const glm::vec3 last = glm::vec3(dims - 1);
  const glm::vec3 c = glm::clamp(g, glm::vec3(0.0f), last);
  const glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(c)), dims - 2);
  const glm::vec3 f = c - glm::vec3(i0);
  // Halved, and the result doubled, exactly, as the shader does (its mix may subtract).
  const auto v = [&](int dx, int dy, int dz) { return 0.5f * at(i0.x + dx, i0.y + dy, i0.z + dz); };
  const float x00 = glm::mix(v(0, 0, 0), v(1, 0, 0), f.x);
  const float x10 = glm::mix(v(0, 1, 0), v(1, 1, 0), f.x);
  const float x01 = glm::mix(v(0, 0, 1), v(1, 0, 1), f.x);
  const float x11 = glm::mix(v(0, 1, 1), v(1, 1, 1), f.x);
  return 2.0f * glm::mix(glm::mix(x00, x10, f.y), glm::mix(x01, x11, f.y), f.z);
}

glm::vec2 VolumeGrid::range() const {
  glm::vec2 r(std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest());
  for (const float v : values)
    if (std::isfinite(v)) r = {std::min(r.x, v), std::max(r.y, v)};
  return r.x <= r.y ? r : glm::vec2(0.0f);
}

void VolumeGrid::validate(const std::string& what) const {
  if (dims.x < 2 || dims.y < 2 || dims.z < 2)
    throw Error(what, "volume needs at least 2 points per axis (got " + std::to_string(dims.x) + "x" +
                          std::to_string(dims.y) + "x" + std::to_string(dims.z) + ")");
  if (dims.x > kMaxPointsPerAxis || dims.y > kMaxPointsPerAxis || dims.z > kMaxPointsPerAxis)
    throw Error(what, "volume larger than " + std::to_string(kMaxPointsPerAxis) + " points per axis");
  const std::size_t n =
      static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(dims.z);
  if (n > kMaxPoints) throw Error(what, "volume of more than 2^30 points");
  if (values.size() != n)
    throw Error(what, "volume has " + std::to_string(values.size()) + " values for " + std::to_string(n) + " points");
  // A double of 1e300 in the file is a float infinity here: say so, not only "non-finite".
  for (const float v : values)
    if (!std::isfinite(v))
      throw Error(what, "volume has a non-finite value (NaN, infinity, or beyond a float's range ±3.4e38)");
}

std::vector<glm::vec4> TransferFunction::table() const {
  std::vector<glm::vec4> out(MFR_VOLUME_TF_SIZE);
  const double lo = low(), hi = high();
  std::size_t seg = 0;
  for (int e = 0; e < MFR_VOLUME_TF_SIZE; ++e) {
    const double v = lo + (hi - lo) * e / (MFR_VOLUME_TF_SIZE - 1);
    while (seg + 2 < points.size() && points[seg + 1].value <= v) ++seg;
    const TransferPoint& a = points[seg];
    const TransferPoint& b = points[seg + 1];
    const double t = b.value > a.value ? std::clamp((v - a.value) / (b.value - a.value), 0.0, 1.0) : 1.0;
    // Entry 0 is also every value below the range (clamped there): the first point's colour, even
    // where a step at the first value gives the second point's just above (it took the step's
    // second colour for the whole range below: a bug hunt).
    const glm::dvec4 c =
        e == 0 ? glm::dvec4(points.front().color) : glm::mix(glm::dvec4(a.color), glm::dvec4(b.color), t);
    const double alpha = std::min(c.a, static_cast<double>(MFR_VOLUME_MAX_ALPHA));
    out[static_cast<std::size_t>(e)] = glm::vec4(glm::vec3(c), static_cast<float>(-std::log1p(-alpha) / unitDistance));
  }
  return out;
}

void TransferFunction::validate(const std::string& what) const {
  if (points.size() < 2) throw Error(what, "transfer function needs at least two points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const TransferPoint& p = points[i];
    if (!std::isfinite(p.value))
      throw Error(what, "transfer function point " + std::to_string(i) + " has a non-finite value");
    // Both renderers take the range as floats: a larger value would be infinite there.
    if (std::abs(p.value) > std::numeric_limits<float>::max())
      throw Error(what, "transfer function point " + std::to_string(i) + " lies beyond a float's range (±3.4e38)");
    for (int c = 0; c < 4; ++c)
      if (!(p.color[c] >= 0.0f && p.color[c] <= 1.0f))
        throw Error(what, "transfer function point " + std::to_string(i) + ": colour and opacity must be in [0, 1]");
    if (i > 0 && p.value < points[i - 1].value)
      throw Error(what, "transfer function values must ascend (point " + std::to_string(i) + ")");
  }
  if (!(high() > low())) throw Error(what, "transfer function range is empty (first value = last value)");
  if (!(unitDistance > 0.0) || !std::isfinite(unitDistance))
    throw Error(what, "transfer function unit distance must be a positive length");
}

const std::vector<std::string>& transferPresetNames() {
  static const std::vector<std::string> names{"grayscale", "bone", "fire", "cool-warm"};
  return names;
}

TransferFunction transferPreset(const std::string& name, double low, double high, double unitDistance) {
  // Control points at fractions of [low, high]: (fraction, r, g, b, opacity).
  struct P {
    double f;
    float r, g, b, a;
  };
  std::vector<P> ps;
  if (name == "grayscale") {
    ps = {{0.0, 0.0f, 0.0f, 0.0f, 0.0f}, {1.0, 1.0f, 1.0f, 1.0f, 0.6f}};
  } else if (name == "bone") {
    // CT numbers: air and fat transparent, soft tissue faint and reddish, bone dense and white.
    ps = {{0.0, 0.0f, 0.0f, 0.0f, 0.0f},      {0.35, 0.55f, 0.25f, 0.15f, 0.0f}, {0.45, 0.85f, 0.45f, 0.35f, 0.08f},
          {0.60, 0.95f, 0.80f, 0.65f, 0.15f}, {0.75, 1.0f, 0.97f, 0.90f, 0.7f},  {1.0, 1.0f, 1.0f, 1.0f, 0.9f}};
  } else if (name == "fire") {
    ps = {{0.0, 0.0f, 0.0f, 0.0f, 0.0f},
          {0.3, 0.6f, 0.05f, 0.0f, 0.1f},
          {0.65, 1.0f, 0.55f, 0.0f, 0.4f},
          {1.0, 1.0f, 1.0f, 0.7f, 0.8f}};
  } else if (name == "cool-warm") {
    // Moreland's diverging map end points and midpoint; opacity grows away from the midpoint.
    ps = {
        {0.0, 0.230f, 0.299f, 0.754f, 0.6f}, {0.5, 0.865f, 0.865f, 0.865f, 0.0f}, {1.0, 0.706f, 0.016f, 0.150f, 0.6f}};
  } else {
    std::string list;
    for (const auto& n : transferPresetNames()) list += (list.empty() ? "" : ", ") + n;
    throw Error("transfer function " + name, "unknown preset (available: " + list + ")");
  }
  TransferFunction tf;
  tf.unitDistance = unitDistance;
  for (const P& p : ps) tf.points.push_back({low + p.f * (high - low), {p.r, p.g, p.b, p.a}});
  return tf;
}

TransferFunction defaultTransfer(const VolumeGrid& grid, const Bounds& worldBounds) {
  const glm::vec2 r = grid.range();
  double low = r.x, high = r.y;
  // A constant volume: a range that floats tell apart (as fieldRange: 1e8 + 1 is 1e8 as a float).
  if (!(high > low)) {
    const double step = std::max(1.0, std::abs(low) * 0x1p-20);
    high = std::min(low + step, static_cast<double>(std::numeric_limits<float>::max()));
    if (!(high > low)) low -= step;
  }
  const double diagonal = worldBounds.valid() ? glm::length(worldBounds.max - worldBounds.min) : 0.0;
  return transferPreset("grayscale", low, high, diagonal > 0.0 && std::isfinite(diagonal) ? diagonal / 50.0 : 1.0);
}

glm::dmat4 Volume::gridToWorld() const {
  return transform * glm::scale(glm::translate(glm::dmat4(1.0), origin), spacing);
}

Bounds Volume::bounds() const {
  Bounds b;
  if (!grid) return b;
  const glm::dmat4 m = gridToWorld();
  const glm::dvec3 last(grid->dims - 1);
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 corner((i & 1) ? last.x : 0.0, (i & 2) ? last.y : 0.0, (i & 4) ? last.z : 0.0);
    b.extend(glm::dvec3(m * glm::dvec4(corner, 1.0)));
  }
  return b;
}

double Volume::defaultStep() const {
  const glm::dmat4 m = gridToWorld();
  const double d =
      std::min({glm::length(glm::dvec3(m[0])), glm::length(glm::dvec3(m[1])), glm::length(glm::dvec3(m[2]))});
  return 0.5 * d;
}

void Volume::validate() const {
  const std::string what = "volume '" + name + "'";
  if (!grid) throw Error(what, "has no grid");
  grid->validate(what);
  for (int a = 0; a < 3; ++a)
    if (!(spacing[a] > 0.0) || !std::isfinite(spacing[a]) || !std::isfinite(origin[a]))
      throw Error(what, "spacing must be positive and the origin finite");
  const double det = glm::determinant(glm::dmat3(gridToWorld()));
  if (!std::isfinite(det) || std::abs(det) < 1e-300) throw Error(what, "transform is singular or not finite");
  // Within ±1e15, as a scene file's coordinates and transforms: a file's own origin of 1e300 was
  // read, and the view's projection degenerated to a blank image.
  const Bounds b = bounds();
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(b.min[a]) <= 1e15 && std::abs(b.max[a]) <= 1e15))
      throw Error(what, "reaches beyond ±1e15 (origin, spacing or transform): it cannot be drawn");
  // Nor below 1e-15 a grid step: the GPU's float march drifted from 1e-20 on and drew nothing at
  // 1e-22, the oracle nothing at 1e-24, with exit 0 (a bug hunt).
  if (const double step = 2.0 * defaultStep(); !(step >= 1e-15))
    throw Error(what, "a grid spacing of " + numberText(step) +
                          " scene units (with its transform) is below 1e-15: too fine to be drawn");
  transfer.validate(what);
}

}  // namespace mfr
