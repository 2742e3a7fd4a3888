#include "mfr/scene/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mfr/error.hpp"

namespace mfr {
namespace {

constexpr double kPi = std::numbers::pi;

std::uint32_t addVertex(Mesh& m, const glm::dvec3& p, const glm::dvec3& n) {
  m.positions.emplace_back(p);
  m.normals.emplace_back(glm::normalize(n));
  return static_cast<std::uint32_t>(m.positions.size() - 1);
}

void addTriangle(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  m.indices.insert(m.indices.end(), {a, b, c});
}

// Grid of (rows+1)×(cols+1) vertices already added starting at base, quads split into two
// counter-clockwise triangles; the caller orders vertices so that (row, col+1) is "right".
void addGrid(Mesh& m, std::uint32_t base, int rows, int cols) {
  const auto idx = [&](int r, int c) { return base + static_cast<std::uint32_t>(r * (cols + 1) + c); };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      addTriangle(m, idx(r, c), idx(r, c + 1), idx(r + 1, c + 1));
      addTriangle(m, idx(r, c), idx(r + 1, c + 1), idx(r + 1, c));
    }
}

// Small deterministic PRNG (splitmix32-style), so generated scenes are identical everywhere.
class Rng {
 public:
  explicit Rng(std::uint32_t seed) : state_(seed * 2654435761u + 0x9E3779B9u) {}
  double uniform() {  // [0, 1)
    std::uint32_t z = (state_ += 0x9E3779B9u);
    z = (z ^ (z >> 16)) * 0x85EBCA6Bu;
    z = (z ^ (z >> 13)) * 0xC2B2AE35u;
    z ^= z >> 16;
    return z / 4294967296.0;
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::uint32_t state_;
};

}  // namespace

Mesh makeSphere(double radius, int slices, int stacks) {
  if (radius <= 0 || slices < 3 || stacks < 2) throw Error("sphere", "radius must be > 0, slices ≥ 3, stacks ≥ 2");
  Mesh m;
  // Rows from the south pole (−Y) to the north pole; columns around +Y, counter-clockwise seen
  // from outside.
  for (int r = 0; r <= stacks; ++r) {
    const double phi = -0.5 * kPi + kPi * r / stacks;
    for (int c = 0; c <= slices; ++c) {
      const double theta = 2.0 * kPi * c / slices;
      const glm::dvec3 n(std::cos(phi) * std::sin(theta), std::sin(phi), std::cos(phi) * std::cos(theta));
      addVertex(m, radius * n, n);
    }
  }
  // Build triangles, skipping the degenerate ones at the poles.
  const auto idx = [&](int r, int c) { return static_cast<std::uint32_t>(r * (slices + 1) + c); };
  for (int r = 0; r < stacks; ++r)
    for (int c = 0; c < slices; ++c) {
      if (r != 0) addTriangle(m, idx(r, c), idx(r, c + 1), idx(r + 1, c + 1));
      if (r != stacks - 1) addTriangle(m, idx(r, c), idx(r + 1, c + 1), idx(r + 1, c));
    }
  return m;
}

Mesh makeBox(const glm::dvec3& size) {
  if (size.x <= 0 || size.y <= 0 || size.z <= 0) throw Error("box", "size must be > 0 in x, y and z");
  Mesh m;
  const glm::dvec3 h = 0.5 * size;
  // Each face: normal n, in-face axes u, v with u × v = n (so u, v order is counter-clockwise).
  const glm::dvec3 faces[6][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                                  {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                                  {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
  for (const auto& f : faces) {
    const glm::dvec3 n = f[0], u = f[1], v = f[2];
    const std::uint32_t base = static_cast<std::uint32_t>(m.positions.size());
    for (int j = 0; j <= 1; ++j)
      for (int i = 0; i <= 1; ++i) addVertex(m, h * (n + (2.0 * i - 1.0) * u + (2.0 * j - 1.0) * v), n);
    addGrid(m, base, 1, 1);
  }
  return m;
}

Mesh makeCylinder(double radius, double height, int slices) {
  if (radius <= 0 || height <= 0 || slices < 3) throw Error("cylinder", "radius and height must be > 0, slices ≥ 3");
  Mesh m;
  const double h = 0.5 * height;
  const std::uint32_t base = static_cast<std::uint32_t>(m.positions.size());
  for (int r = 0; r <= 1; ++r)
    for (int c = 0; c <= slices; ++c) {
      const double t = 2.0 * kPi * c / slices;
      const glm::dvec3 n(std::sin(t), 0.0, std::cos(t));
      addVertex(m, glm::dvec3(radius * n.x, r == 0 ? -h : h, radius * n.z), n);
    }
  addGrid(m, base, 1, slices);
  for (int capSide = 0; capSide <= 1; ++capSide) {
    const double y = capSide == 0 ? -h : h;
    const glm::dvec3 n(0.0, capSide == 0 ? -1.0 : 1.0, 0.0);
    const std::uint32_t centre = addVertex(m, glm::dvec3(0.0, y, 0.0), n);
    const std::uint32_t ring = static_cast<std::uint32_t>(m.positions.size());
    for (int c = 0; c < slices; ++c) {
      const double t = 2.0 * kPi * c / slices;
      addVertex(m, glm::dvec3(radius * std::sin(t), y, radius * std::cos(t)), n);
    }
    for (int c = 0; c < slices; ++c) {
      const std::uint32_t a = ring + static_cast<std::uint32_t>(c);
      const std::uint32_t b = ring + static_cast<std::uint32_t>((c + 1) % slices);
      // Angle increases counter-clockwise seen from +Y: top cap (a, b) order, bottom reversed.
      if (capSide == 1)
        addTriangle(m, centre, a, b);
      else
        addTriangle(m, centre, b, a);
    }
  }
  return m;
}

Mesh makeTorus(double majorRadius, double minorRadius, int majorSegments, int minorSegments) {
  if (majorRadius <= 0 || minorRadius <= 0 || minorRadius >= majorRadius || majorSegments < 3 || minorSegments < 3)
    throw Error("torus", "need 0 < minor radius < major radius and ≥ 3 segments");
  Mesh m;
  // Rows follow the minor circle, columns the major circle (around +Y).
  for (int r = 0; r <= minorSegments; ++r) {
    const double phi = 2.0 * kPi * r / minorSegments;
    for (int c = 0; c <= majorSegments; ++c) {
      const double theta = 2.0 * kPi * c / majorSegments;
      const glm::dvec3 radial(std::sin(theta), 0.0, std::cos(theta));
      const glm::dvec3 n = std::cos(phi) * radial + std::sin(phi) * glm::dvec3(0, 1, 0);
      addVertex(m, majorRadius * radial + minorRadius * n, n);
    }
  }
  // Columns advance theta (u), rows advance phi (v): u × v points along the outward normal.
  addGrid(m, 0, minorSegments, majorSegments);
  return m;
}

Mesh makePlane(double width, double height) {
  if (width <= 0 || height <= 0) throw Error("plane", "width and height must be > 0");
  Mesh m;
  const glm::dvec3 n(0, 0, 1);
  for (int j = 0; j <= 1; ++j)
    for (int i = 0; i <= 1; ++i) addVertex(m, glm::dvec3((i - 0.5) * width, (j - 0.5) * height, 0.0), n);
  addGrid(m, 0, 1, 1);
  return m;
}

Mesh makeTube(const std::vector<glm::dvec3>& path, double radius, int sides) {
  if (path.size() < 2 || radius <= 0 || sides < 3) throw Error("tube", "need ≥ 2 path points, radius > 0, sides ≥ 3");
  Mesh m;
  // Parallel-transport frames along the path: no twisting, no flips at inflections.
  std::vector<glm::dvec3> tangents(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    const glm::dvec3 d = path[std::min(i + 1, path.size() - 1)] - path[i == 0 ? 0 : i - 1];
    if (glm::length(d) <= 0.0) throw Error("tube", "repeated path point");
    tangents[i] = glm::normalize(d);
  }
  glm::dvec3 normal =
      glm::cross(tangents[0], std::abs(tangents[0].y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0));
  normal = glm::normalize(normal);
  const std::uint32_t base = static_cast<std::uint32_t>(m.positions.size());
  std::vector<std::pair<glm::dvec3, glm::dvec3>> frames;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0) {
      normal -= tangents[i] * glm::dot(normal, tangents[i]);
      normal = glm::normalize(normal);
    }
    const glm::dvec3 binormal = glm::cross(tangents[i], normal);
    frames.emplace_back(normal, binormal);
    for (int s = 0; s <= sides; ++s) {
      const double a = 2.0 * kPi * s / sides;
      const glm::dvec3 n = std::cos(a) * normal + std::sin(a) * binormal;
      addVertex(m, path[i] + radius * n, n);
    }
  }
  // Columns advance the angle (u ∝ b at angle 0, b = t × n), rows advance along the path (v ∝ t):
  // u × v = (t × n) × t = n, outward.
  addGrid(m, base, static_cast<int>(path.size()) - 1, sides);
  // Caps: flat discs at both ends, facing −t at the start and +t at the end.
  for (int end = 0; end <= 1; ++end) {
    const std::size_t i = end == 0 ? 0 : path.size() - 1;
    const glm::dvec3 n = end == 0 ? -tangents[i] : tangents[i];
    const std::uint32_t centre = addVertex(m, path[i], n);
    const std::uint32_t ring = static_cast<std::uint32_t>(m.positions.size());
    for (int s = 0; s < sides; ++s) {
      const double a = 2.0 * kPi * s / sides;
      addVertex(m, path[i] + radius * (std::cos(a) * frames[i].first + std::sin(a) * frames[i].second), n);
    }
    for (int s = 0; s < sides; ++s) {
      const std::uint32_t a = ring + static_cast<std::uint32_t>(s);
      const std::uint32_t b = ring + static_cast<std::uint32_t>((s + 1) % sides);
      // The angle runs counter-clockwise around +t (n → b = t × n), so seen from +t: (a, b).
      if (end == 1)
        addTriangle(m, centre, a, b);
      else
        addTriangle(m, centre, b, a);
    }
  }
  return m;
}

Mesh makeHairball(int count, double radius, double tubeRadius, std::uint32_t seed, int segments, int sides) {
  if (count < 1 || radius <= 0 || tubeRadius <= 0 || segments < 2)
    throw Error("hairball", "need count ≥ 1, radius > 0, tube radius > 0, segments ≥ 2");
  Rng rng(seed);
  Mesh all;
  for (int h = 0; h < count; ++h) {
    // A smooth closed-ish curve: sum of two random great-circle-like oscillations, scaled to stay
    // inside the sphere (|p| ≤ radius − tubeRadius).
    glm::dvec3 a(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    glm::dvec3 b(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    glm::dvec3 c(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const double f1 = rng.uniform(0.5, 1.5), f2 = rng.uniform(1.5, 3.0), p0 = rng.uniform(0, 2 * kPi);
    const double span = rng.uniform(1.2, 2.0) * kPi;
    std::vector<glm::dvec3> path;
    for (int s = 0; s <= segments; ++s) {
      const double t = p0 + span * s / segments;
      glm::dvec3 p = a * std::sin(f1 * t) + b * std::cos(f1 * t) + 0.35 * c * std::sin(f2 * t);
      path.push_back(p);
    }
    double maxLen = 0.0;
    for (const glm::dvec3& p : path) maxLen = std::max(maxLen, glm::length(p));
    const double scale = (radius - tubeRadius) / std::max(maxLen, 1e-9);
    for (glm::dvec3& p : path) p *= scale;
    Mesh tube = makeTube(path, tubeRadius, sides);
    const std::uint32_t base = static_cast<std::uint32_t>(all.positions.size());
    all.positions.insert(all.positions.end(), tube.positions.begin(), tube.positions.end());
    all.normals.insert(all.normals.end(), tube.normals.begin(), tube.normals.end());
    for (std::uint32_t i : tube.indices) all.indices.push_back(base + i);
  }
  return all;
}

}  // namespace mfr
