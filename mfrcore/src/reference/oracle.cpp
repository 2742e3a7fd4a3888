// The CPU fragment oracle: exact per-pixel fragment lists by ray casting (double precision),
// independent of any GPU code.
//
// Candidates (the broad phase): each triangle's window polygon, clipped to slightly widened near
// and far planes, is binned to every pixel centre of the region within a pad of it (kBinPad plus
// the cast rays' measured stray); a pixel's rays are tested only against its bin. A ray that hits a triangle at a depth
// in [0, 1] passes through that polygon, so the bins miss no hit, and each holds what covers the pixel (the fragments,
// plus a sliver of pad) — unlike a world-space box tree, whose boxes of long thin triangles (a fan's slivers around its
// hub) each hold thousands of pixels they do not cover.
//
// Rays: one per pixel centre. Pixel (x, y) of the image (y = 0 is the top row) is the GL window
// point (x + 0.5, height − 1 − y + 0.5); its ray runs from the unprojected near-plane point to the
// unprojected far-plane point through inverse(P·V), which gives eye rays for perspective and
// parallel rays for orthographic cameras. Every hit with window depth in [0, 1] becomes a fragment
// (depth = 0.5·clip.z/clip.w + 0.5 of the hit point), shaded with mfrShade from
// shaders/common/shading.h; lists are sorted by depth, ties by object id, then triangle index.
//
// Edge rule (FragmentLists::kEdge): every visible triangle of non-zero world area is clipped in
// clip space to the near and far planes (z ≥ −w, z ≤ w) and projected to window coordinates; a
// pixel is an edge pixel when its centre lies within edgeEpsilon pixels (Euclidean distance in
// window coordinates) of a side or vertex of that clipped polygon — whether its ray hits the
// triangle or not. Sides created by the clipping count too (GL clips there). A triangle whose
// clipped window area is below kMinScreenArea px² (edge-on) produces no fragments on the GPU, so
// ray hits on it are dropped and their pixels marked kEdge (such pixels are also always within
// epsilon of its sides). kDepthTie: two consecutive fragments of a pixel whose depths differ by
// less than depthTieEpsilon·max(1e-30, |depth|).
#include "mfr/reference/oracle.hpp"

#include "reference/pixel_region.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include <glm/gtc/packing.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/section.hpp"

namespace mfr::shading {
using namespace glm;
#include "common/shading.h"
}  // namespace mfr::shading

namespace mfr {
namespace {

constexpr int kMaxImageSize = 16384;
// Below this window-space area (px²) GL rasterises a triangle as nothing (edge-on).
constexpr double kMinScreenArea = 1e-6;
// Broad phase: a pixel centre within this many pixels of a triangle's window polygon (plus a
// relative kBinPadRelative of the polygon's largest coordinate, plus twice the measured stray of
// the cast rays) is a candidate. The ray through a centre and the projection of the triangle
// agree to rounding (about 1e-9 px here), so the pad only has to be safe; each pixel it adds
// costs one more exact test.
constexpr double kBinPad = 0.05;
constexpr double kBinPadRelative = 1e-9;
// The bins' near and far planes are widened by this (relative to w): a hit whose double-precision
// depth lands in [0, 1] by rounding is still binned.
constexpr double kBinDepthSlack = 1e-6;

// A visible, non-degenerate triangle in world space plus what shading needs.
struct WorldTriangle {
  glm::dvec3 p[3];
  std::uint32_t objectId = 0;
  std::uint32_t vertex[3] = {0, 0, 0};  // indices into the object's mesh
};

struct ObjectShading {
  const Mesh* mesh = nullptr;
  glm::dmat3 normalMatrix{1.0};  // inverse transpose of the object transform's linear part
  glm::vec4 materialColor{1.0f};
  bool vertexColors = true;  // Material::vertexColors
  // Material::fieldColors with the mesh's scalars there: the map and its range; else null.
  const ColorMap* colorMap = nullptr;
  glm::vec2 colorMapRange{0.0f, 1.0f};
  // Coloured by a volume: sampled at the hit, not interpolated from the vertices (VolumeFieldSampler).
  std::optional<VolumeFieldSampler> fieldSampler;
};

struct Hit {
  double depth;
  std::uint32_t objectId;
  std::uint32_t triangle;
  Fragment fragment;
};

glm::dvec3 transformPoint(const glm::dmat4& m, const glm::dvec3& p) {
  const glm::dvec4 h = m * glm::dvec4(p, 1.0);
  // Affine transforms have w = 1; divide anyway so a projective one still means what it says.
  return glm::dvec3(h) / h.w;
}

// A polygon of at most 12 points, on the stack: a triangle clipped by two planes. Each of its
// sides adds at most two points per clip, so 3 → 6 → 12 holds even when rounding makes a clipped
// polygon not quite convex. (The oracle computes millions of these per image, three times each.)
template <class Point>
struct SmallPolygon {
  std::array<Point, 12> points{};
  std::size_t count = 0;
  void push_back(const Point& p) { points[count++] = p; }
  [[nodiscard]] std::size_t size() const { return count; }
  [[nodiscard]] bool empty() const { return count == 0; }
  const Point& operator[](std::size_t i) const { return points[i]; }
  [[nodiscard]] const Point* begin() const { return points.data(); }
  [[nodiscard]] const Point* end() const { return points.data() + count; }
};
using ClipPolygon = SmallPolygon<glm::dvec4>;
using WindowPolygon = SmallPolygon<glm::dvec2>;

// Sutherland–Hodgman against one clip-space plane dot(plane, v) ≥ 0.
ClipPolygon clipPolygon(const ClipPolygon& in, const glm::dvec4& plane) {
  ClipPolygon out;
  const std::size_t n = in.size();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec4& a = in[i];
    const glm::dvec4& b = in[(i + 1) % n];
    const double da = glm::dot(plane, a);
    const double db = glm::dot(plane, b);
    if (da >= 0.0) out.push_back(a);
    if ((da >= 0.0) != (db >= 0.0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

// Window coordinates of a clip-space point.
glm::dvec2 toWindow(const glm::dvec4& c, int width, int height) {
  return {(0.5 * c.x / c.w + 0.5) * width, (0.5 * c.y / c.w + 0.5) * height};
}

// The triangle's footprint in window coordinates after clipping to the near and far planes
// (z ≥ −(1 + slack)·w, z ≤ (1 + slack)·w). `inFront` is false when a clipped point still is not
// in front of the eye (w ≤ 0) or not finite, which our cameras never give: the footprint is then
// empty.
WindowPolygon windowPolygon(const WorldTriangle& t, const glm::dmat4& viewProj, int width, int height,
                            double slack = 0.0, bool* inFront = nullptr) {
  if (inFront != nullptr) *inFront = true;
  ClipPolygon poly;
  for (const glm::dvec3& p : t.p) poly.push_back(viewProj * glm::dvec4(p, 1.0));
  poly = clipPolygon(poly, glm::dvec4(0.0, 0.0, 1.0, 1.0 + slack));                      // near
  if (!poly.empty()) poly = clipPolygon(poly, glm::dvec4(0.0, 0.0, -1.0, 1.0 + slack));  // far
  WindowPolygon window;
  for (const glm::dvec4& c : poly) {
    const glm::dvec2 w = toWindow(c, width, height);
    if (!(c.w > 0.0) || !std::isfinite(w.x) || !std::isfinite(w.y)) {
      if (inFront != nullptr) *inFront = false;
      return {};
    }
    window.push_back(w);
  }
  return window;
}

// The x values at the ends of segment ab's part inside the band |y − yc| ≤ eps (in any order);
// false when no part of it lies in the band.
bool segmentInBand(const glm::dvec2& a, const glm::dvec2& b, double yc, double eps, double& x0, double& x1) {
  const glm::dvec2 d = b - a;
  double t0 = 0.0;
  double t1 = 1.0;
  if (d.y != 0.0) {
    t0 = (yc - eps - a.y) / d.y;
    t1 = (yc + eps - a.y) / d.y;
    if (t0 > t1) std::swap(t0, t1);
    t0 = std::max(t0, 0.0);
    t1 = std::min(t1, 1.0);
    if (t0 > t1) return false;
  } else if (std::abs(a.y - yc) > eps) {
    return false;
  }
  x0 = a.x + t0 * d.x;
  x1 = a.x + t1 * d.x;
  return true;
}

// Calls visit(pixel index) for every pixel of `region` whose centre lies within `pad` of the
// convex window polygon `poly` (any number of points; as a closed loop). A row's x range is that
// of the polygon's sides inside the band of rows within pad of its centre line, widened by pad:
// the extent of the band's slice of a convex polygon lies on its sides.
template <class Visit>
void forPixelsNearPolygon(const WindowPolygon& poly, double pad, int height, const PixelRect& region, int width,
                          Visit&& visit) {
  if (poly.empty()) return;
  double ymin = poly[0].y;
  double ymax = poly[0].y;
  for (const glm::dvec2& p : poly) {
    ymin = std::min(ymin, p.y);
    ymax = std::max(ymax, p.y);
  }
  // Window row r has its centre at r + 0.5; image row y is window row height - 1 - y.
  const double rowLo = std::max(static_cast<double>(height - region.y - region.height), std::ceil(ymin - pad - 0.5));
  const double rowHi = std::min(static_cast<double>(height - 1 - region.y), std::floor(ymax + pad - 0.5));
  if (!(rowLo <= rowHi)) return;
  const std::size_t n = poly.size();
  for (int row = static_cast<int>(rowLo); row <= static_cast<int>(rowHi); ++row) {
    const double yc = row + 0.5;
    double xmin = std::numeric_limits<double>::infinity();
    double xmax = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      double x0 = 0.0;
      double x1 = 0.0;
      if (!segmentInBand(poly[i], poly[(i + 1) % n], yc, pad, x0, x1)) continue;
      xmin = std::min({xmin, x0, x1});
      xmax = std::max({xmax, x0, x1});
    }
    const double xLo = std::max(static_cast<double>(region.x), std::ceil(xmin - pad - 0.5));
    const double xHi = std::min(static_cast<double>(region.x + region.width - 1), std::floor(xmax + pad - 0.5));
    if (!(xLo <= xHi)) continue;
    const std::size_t rowBase = static_cast<std::size_t>(height - 1 - row) * width;  // image rows top-down
    for (int col = static_cast<int>(xLo); col <= static_cast<int>(xHi); ++col) visit(rowBase + col);
  }
}

// Calls visit(pixel index) for every pixel of `region` whose ray may hit the triangle at a depth
// in [0, 1]: those within `pad` of its widened window polygon, or, should the projection fail,
// all of them.
template <class Visit>
void forCandidatePixels(const WorldTriangle& t, const glm::dmat4& viewProj, int width, int height,
                        const PixelRect& region, double pad, Visit&& visit) {
  bool inFront = true;
  const WindowPolygon poly = windowPolygon(t, viewProj, width, height, kBinDepthSlack, &inFront);
  if (!inFront || !std::isfinite(pad)) {
    for (int y = region.y; y < region.y + region.height; ++y)
      for (int x = region.x; x < region.x + region.width; ++x) visit(static_cast<std::size_t>(y) * width + x);
    return;
  }
  double largest = 0.0;
  for (const glm::dvec2& p : poly) largest = std::max({largest, std::abs(p.x), std::abs(p.y)});
  forPixelsNearPolygon(poly, pad + kBinPadRelative * largest, height, region, width, visit);
}

double polygonArea(const WindowPolygon& poly) {
  double a = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2& p = poly[i];
    const glm::dvec2& q = poly[(i + 1) % poly.size()];
    a += p.x * q.y - q.x * p.y;
  }
  return 0.5 * std::abs(a);
}

double distanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
  const glm::dvec2 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

// Marks every pixel whose centre lies within eps of segment ab. Rows are walked over the
// segment's extent; in each row only the x range of segment points within eps vertically
// (widened by eps) can qualify, so long edges cost O(length), not O(bounding box). Only pixels of
// `region` (image coordinates, not empty) are marked.
void markSegment(const glm::dvec2& a, const glm::dvec2& b, double eps, int width, int height, const PixelRect& region,
                 std::vector<std::uint8_t>& flags) {
  const double ymin = std::min(a.y, b.y) - eps;
  const double ymax = std::max(a.y, b.y) + eps;
  // Window row r has its centre at r + 0.5; image row y is window row height - 1 - y.
  const double rowLo = std::max(static_cast<double>(height - region.y - region.height), std::ceil(ymin - 0.5));
  const double rowHi = std::min(static_cast<double>(height - 1 - region.y), std::floor(ymax - 0.5));
  if (!(rowLo <= rowHi)) return;
  for (int row = static_cast<int>(rowLo); row <= static_cast<int>(rowHi); ++row) {
    const double yc = row + 0.5;
    double x0 = 0.0;
    double x1 = 0.0;
    if (!segmentInBand(a, b, yc, eps, x0, x1)) continue;
    const double xLo = std::max(static_cast<double>(region.x), std::ceil(std::min(x0, x1) - eps - 0.5));
    const double xHi =
        std::min(static_cast<double>(region.x + region.width - 1), std::floor(std::max(x0, x1) + eps - 0.5));
    if (!(xLo <= xHi)) continue;
    const std::size_t rowBase = static_cast<std::size_t>(height - 1 - row) * width;  // image rows top-down
    for (int col = static_cast<int>(xLo); col <= static_cast<int>(xHi); ++col)
      if (distanceToSegment(glm::dvec2(col + 0.5, yc), a, b) <= eps)  // several threads mark flags at once
        std::atomic_ref<std::uint8_t>(flags[rowBase + col]).fetch_or(FragmentLists::kEdge, std::memory_order_relaxed);
  }
}

// Calls work(i) for i in [0, count) on `threads` threads (this one included), items handed out in
// chunks of `chunk`; the first exception stops the others and is rethrown here.
void runParallel(unsigned threads, std::size_t count, std::size_t chunk, const std::function<void(std::size_t)>& work) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failureMutex;
  const auto worker = [&] {
    try {
      for (std::size_t begin = next.fetch_add(chunk); begin < count; begin = next.fetch_add(chunk))
        for (std::size_t i = begin; i < std::min(count, begin + chunk); ++i) work(i);
    } catch (...) {
      const std::lock_guard lock(failureMutex);
      if (!failure) failure = std::current_exception();
      next = count;  // stop the others early
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

// Ray/triangle intersection, watertight (Woop, Benthin, Wald, "Watertight Ray/Triangle
// Intersection", JCGT 2(1) 2013), in double: barycentrics (u, v) of p[1] and p[2]. The vertices
// are sheared into the ray's frame and the three edge functions are 2D cross products of the
// same two vertices for every triangle sharing an edge, so a shared edge's value in one is
// exactly the negation of its value in the other. A ray exactly on an edge or a vertex belongs to
// the triangle whose edge there passes a fixed tie rule (a top-left rule, as GL's rasteriser has):
// with Möller–Trumbore's inclusive bounds such a ray hit every triangle there, so a unit cube's
// front view counted 4 fragments at its corners and a two-triangle plane 2 on its diagonal (a
// bug hunt). Rays in the triangle's plane count as misses (GL draws edge-on triangles as nothing).
bool intersect(const glm::dvec3& origin, const glm::dvec3& dir, const WorldTriangle& tri, double& u, double& v) {
  const glm::dvec3 a = glm::abs(dir);
  const int kz = a.x >= a.y ? (a.x >= a.z ? 0 : 2) : (a.y >= a.z ? 1 : 2);
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (dir[kz] < 0.0) std::swap(kx, ky);  // keeps the winding of the sheared triangle
  if (dir[kz] == 0.0) return false;
  const double sx = dir[kx] / dir[kz], sy = dir[ky] / dir[kz];
  glm::dvec2 q[3];
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3 r = tri.p[i] - origin;
    q[i] = {r[kx] - sx * r[kz], r[ky] - sy * r[kz]};
  }
  // e[i]: the edge opposite vertex i, from vertex i+1 to vertex i+2.
  const double e[3] = {q[2].x * q[1].y - q[2].y * q[1].x, q[0].x * q[2].y - q[0].y * q[2].x,
                       q[1].x * q[0].y - q[1].y * q[0].x};
  if (!std::isfinite(e[0]) || !std::isfinite(e[1]) || !std::isfinite(e[2])) return false;
  const bool anyNegative = e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0;
  const bool anyPositive = e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0;
  if (anyNegative && anyPositive) return false;
  const double det = e[0] + e[1] + e[2];
  if (det == 0.0 || !std::isfinite(det)) return false;  // finite parts can sum past a double (a review)
  // On an edge (a zero edge function): the edge's direction, turned so the triangle lies to its
  // right, must point up, or left when level. Of two triangles on either side of an edge exactly
  // one passes; at a vertex exactly one of those around it (a consistent infinitesimal shift).
  const double sign = det > 0.0 ? 1.0 : -1.0;
  for (int i = 0; i < 3; ++i) {
    if (e[i] != 0.0) continue;
    const glm::dvec2 d = sign * (q[(i + 2) % 3] - q[(i + 1) % 3]);
    if (!(d.y > 0.0 || (d.y == 0.0 && d.x < 0.0))) return false;
  }
  u = e[1] / det;
  v = e[2] / det;
  return true;
}

std::uint32_t shade(const WorldTriangle& tri, const ObjectShading& obj, double u, double v, const glm::vec3& viewDir) {
  const double w[3] = {1.0 - u - v, u, v};
  const Mesh& mesh = *obj.mesh;
  // A mesh without normals gets object-space +Z, as the GPU upload (gl/gpu_scene.cpp) does.
  glm::dvec3 n(0.0, 0.0, 1.0);
  if (mesh.normals.size() == mesh.positions.size()) {
    n = glm::dvec3(0.0);
    for (int k = 0; k < 3; ++k) n += w[k] * glm::dvec3(mesh.normals[tri.vertex[k]]);
  }
  // Opposite vertex normals can cancel: fall back to the face normal rather than let normalize()
  // produce NaN (the GPU's result is undefined there anyway). Tested on the object's own (unit)
  // normals: after a scale of 1e12 along one axis, a transformed normal may be 1e-12 long.
  glm::dvec3 normal = obj.normalMatrix * n;
  if (!(glm::dot(n, n) > 1e-24) || !(glm::dot(normal, normal) > 0.0) || !std::isfinite(glm::dot(normal, normal)))
    normal = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
  glm::vec4 base = obj.materialColor;
  if (obj.colorMap != nullptr) {
    // Interpolated, then mapped, as common/color_map.glsl does (in float, as the GPU's varying); a
    // volume's value sampled at the hit and bounded, as common/fragment.glsl does.
    float value = 0.0f;
    if (obj.fieldSampler) {
      glm::dvec3 p(0.0);
      for (int k = 0; k < 3; ++k) p += w[k] * glm::dvec3(mesh.positions[tri.vertex[k]]);
      value = boundFieldValue(obj.fieldSampler->at(p), obj.colorMapRange);
    } else {
      for (int k = 0; k < 3; ++k)
        value += static_cast<float>(w[k]) * boundFieldValue(mesh.scalars[tri.vertex[k]], obj.colorMapRange);
    }
    base = glm::vec4(mapFieldValue(*obj.colorMap, value, obj.colorMapRange), base.a);
  } else if (obj.vertexColors && mesh.colors.size() == mesh.positions.size()) {
    glm::dvec4 c(0.0);
    for (int k = 0; k < 3; ++k) c += w[k] * glm::dvec4(mesh.colors[tri.vertex[k]]);
    base *= glm::vec4(c);
  }
  return glm::packUnorm4x8(shading::mfrShade(base, glm::vec3(normal), viewDir));
}

// The camera-independent part of the oracle: world-space triangles of the visible objects (with
// zero-area ones dropped). The viewer, mfr evaluate and mfr dataset cast many images of one
// scene, so the last geometry is kept and reused while its key matches.
struct GeometryKey {
  struct Part {
    std::size_t object = 0;  // becomes the fragments' objectId
    glm::dmat4 transform{1.0};
    std::size_t vertices = 0;
    std::size_t indices = 0;
    std::uint64_t contentHash = 0;  // positions and indices, so an edited mesh never matches
    bool operator==(const Part&) const = default;
  };
  std::vector<Part> parts;
  bool operator==(const GeometryKey&) const = default;
};

struct PreparedGeometry {
  GeometryKey key;
  std::vector<WorldTriangle> triangles;
};

// FNV-1a over 32-bit words: a few milliseconds for millions of vertices.
std::uint64_t hashWords(const void* data, std::size_t bytes, std::uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint32_t word = 0;
  for (std::size_t i = 0; i + 4 <= bytes; i += 4) {
    std::memcpy(&word, p + i, 4);
    h = (h ^ word) * 1099511628211ull;
  }
  return h;
}

GeometryKey geometryKey(const Scene& scene) {
  GeometryKey key;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    if (!object.visible || !object.mesh || object.mesh->triangleCount() == 0) continue;
    const Mesh& mesh = *object.mesh;
    std::uint64_t h = 14695981039346656037ull;
    h = hashWords(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3), h);
    h = hashWords(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t), h);
    key.parts.push_back({o, object.transform, mesh.positions.size(), mesh.indices.size(), h});
  }
  return key;
}

void checkImageSize(int width, int height) {
  if (width <= 0 || height <= 0 || width > kMaxImageSize || height > kMaxImageSize)
    throw Error("image size", std::to_string(width) + "x" + std::to_string(height) + " is not in 1.." +
                                  std::to_string(kMaxImageSize) + " per side");
}

// Zero world area (relative to the edge lengths): no plane, no fragments, no edges.
bool hasArea(const glm::dvec3 (&p)[3]) {
  const double area2 = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
  const double edge2 = std::max(
      {glm::dot(p[1] - p[0], p[1] - p[0]), glm::dot(p[2] - p[1], p[2] - p[1]), glm::dot(p[0] - p[2], p[0] - p[2])});
  return area2 > 1e-14 * edge2;
}

// The camera's inverse view-projection, refused when not finite.
glm::dmat4 invertibleViewProjection(const Camera& camera, int width, int height, glm::dmat4& viewProj) {
  viewProj = camera.projectionMatrix(static_cast<double>(width) / height) * camera.viewMatrix();
  const glm::dmat4 inverse = glm::inverse(viewProj);
  const double* m = glm::value_ptr(inverse);
  if (!std::all_of(m, m + 16, [](double x) { return std::isfinite(x); }))
    throw Error("camera", "projection is singular (check near/far planes, field of view and up vector)");
  return inverse;
}

std::shared_ptr<const PreparedGeometry> buildGeometry(const Scene& scene, GeometryKey key) {
  auto geometry = std::make_shared<PreparedGeometry>();
  std::vector<WorldTriangle>& triangles = geometry->triangles;
  for (const GeometryKey::Part& part : key.parts) {
    const Mesh& mesh = *scene.objects[part.object].mesh;
    std::vector<glm::dvec3> world(mesh.positions.size());
    for (std::size_t i = 0; i < world.size(); ++i)
      world[i] = transformPoint(part.transform, glm::dvec3(mesh.positions[i]));
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      WorldTriangle tri;
      tri.objectId = static_cast<std::uint32_t>(part.object);
      for (int k = 0; k < 3; ++k) {
        tri.vertex[k] = mesh.indices[3 * t + k];
        tri.p[k] = world[tri.vertex[k]];
      }
      if (!hasArea(tri.p)) continue;
      triangles.push_back(tri);
    }
  }
  geometry->key = std::move(key);
  return geometry;
}

// The last scene's geometry, or a new one. Two threads may build at once; the last one is kept.
std::shared_ptr<const PreparedGeometry> preparedGeometry(const Scene& scene) {
  static std::mutex mutex;
  static std::shared_ptr<const PreparedGeometry> last;
  GeometryKey key = geometryKey(scene);
  {
    const std::lock_guard lock(mutex);
    if (last && last->key == key) return last;
  }
  std::shared_ptr<const PreparedGeometry> geometry = buildGeometry(scene, std::move(key));
  const std::lock_guard lock(mutex);
  last = geometry;
  return geometry;
}

}  // namespace

void checkDrawable(const Scene& scene, const Camera& camera, int width, int height, const std::string& what) {
  checkImageSize(width, height);
  glm::dmat4 viewProj(1.0);
  (void)invertibleViewProjection(camera, width, height, viewProj);
  bool drawable = scene.hasVisibleVolume();
  std::size_t flat = 0;  // visible triangles without area, for the message
  for (const Object& object : scene.objects) {
    if (!object.visible || !object.mesh || object.mesh->triangleCount() == 0) continue;
    object.mesh->validate(object.name);
    const Mesh& mesh = *object.mesh;
    for (std::size_t t = 0; !drawable && t < mesh.triangleCount(); ++t) {
      glm::dvec3 p[3];
      for (int k = 0; k < 3; ++k)
        p[k] = transformPoint(object.transform, glm::dvec3(mesh.positions[mesh.indices[3 * t + k]]));
      drawable = hasArea(p);
      if (!drawable) ++flat;
    }
  }
  // "No visible triangles" was wrong for a file whose triangles are all degenerate (collinear).
  if (!drawable)
    throw Error(what.empty() ? "scene '" + scene.name + "'" : what,
                flat == 0   ? std::string("nothing to render (no visible triangles)")
                : flat == 1 ? std::string("nothing to render (its one visible triangle is degenerate: no area)")
                            : "nothing to render (its " + std::to_string(flat) +
                                  " visible triangles are all degenerate: no area)");
}

FragmentLists castFragments(const Scene& scene, const Camera& camera, int width, int height,
                            const OracleOptions& options) {
  // A section plane is applied as geometry, as the GPU renderer does (scene/section.hpp).
  if (scene.section && !scene.sectionCut) return castFragments(sectionedScene(scene), camera, width, height, options);
  checkImageSize(width, height);

  const PixelRect region = regionInImage(options.region, width, height);

  glm::dmat4 viewProj(1.0);
  const glm::dmat4 invViewProj = invertibleViewProjection(camera, width, height, viewProj);

  // Material and normal transform of every visible object (cheap, per call: colours change
  // without the geometry changing).
  std::vector<ObjectShading> objects(scene.objects.size());
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    if (!object.visible || !object.mesh || object.mesh->triangleCount() == 0) continue;
    object.mesh->validate(object.name);
    ObjectShading& shading = objects[o];
    shading.mesh = object.mesh.get();
    shading.normalMatrix = normalMatrix(object.transform);
    shading.materialColor = object.material.color;
    shading.vertexColors = object.material.vertexColors;
    if (const std::optional<FieldColors>& field = object.material.fieldColors;
        field && object.mesh->scalars.size() == object.mesh->positions.size()) {
      objects[o].colorMap = &colorMap(field->map);
      objects[o].colorMapRange = glm::vec2(field->range);
      objects[o].fieldSampler = volumeFieldSampler(scene, object);
    }
  }
  const std::shared_ptr<const PreparedGeometry> geometry = preparedGeometry(scene);
  const std::vector<WorldTriangle>& triangles = geometry->triangles;
  FragmentLists lists;
  lists.width = width;
  lists.height = height;
  const std::size_t pixelCount = static_cast<std::size_t>(width) * height;
  const std::string listsOfSize =
      "the exact fragment lists of " + std::to_string(width) + "x" + std::to_string(height) + " pixels";
  // Per pixel: flags, bin counts and offsets, hit counts, ray flags and the lists' offsets.
  requireHostMemory("oracle", listsOfSize, pixelCount * 18);
  lists.flags.assign(pixelCount, 0);
  if (triangles.empty()) {
    // A scene of volumes only: every list is empty.
    if (!scene.hasVisibleVolume()) {
      checkDrawable(scene, camera, width, height);  // says why: degenerate triangles, or none
      throw Error("scene '" + scene.name + "'", "nothing to render (no visible triangles)");
    }
    lists.offsets.assign(pixelCount + 1, 0);
    return lists;
  }

  unsigned threadCount =
      options.threads > 0 ? static_cast<unsigned>(options.threads) : std::thread::hardware_concurrency();
  threadCount = std::max(threadCount, 1u);

  // The ray through window point (wx, wy): origin on the near plane, dir to the far plane — or,
  // where the far plane lies beyond double's reach of the near one (near 0.01, far 1e30: its
  // point's w is (f + n) − (f − n) = 0, and the ray was infinite, hitting nothing: a blank
  // reference, review 29), to the mid-depth point of the same line.
  const auto windowRay = [&](double wx, double wy, glm::dvec3& origin, glm::dvec3& dir) {
    const double ndcX = 2.0 * wx / width - 1.0;
    const double ndcY = 2.0 * wy / height - 1.0;
    const glm::dvec4 n4 = invViewProj * glm::dvec4(ndcX, ndcY, -1.0, 1.0);
    origin = glm::dvec3(n4) / n4.w;
    const glm::dvec4 f4 = invViewProj * glm::dvec4(ndcX, ndcY, 1.0, 1.0);
    glm::dvec3 end = glm::dvec3(f4) / f4.w;
    if (!std::isfinite(end.x) || !std::isfinite(end.y) || !std::isfinite(end.z)) {
      const glm::dvec4 m4 = invViewProj * glm::dvec4(ndcX, ndcY, 0.0, 1.0);
      end = glm::dvec3(m4) / m4.w;
    }
    dir = end - origin;
  };
  // How far the rays as cast stray from their pixel centres, in window pixels: the largest distance
  // of a ray's projected ends from its centre, over the region. A point of the segment projects
  // between its ends, so the bins widened by this hold every triangle the cast rays can hit. It is
  // about 1e-9 px; only absurd cameras (near plane 1e-9 at 3e6 from the origin) make it matter.
  double rayDrift = 0.0;
  for (int y = region.y; y < region.y + region.height; ++y)
    for (int x = region.x; x < region.x + region.width; ++x) {
      const glm::dvec2 centre(x + 0.5, (height - 1 - y) + 0.5);
      glm::dvec3 origin, dir;
      windowRay(centre.x, centre.y, origin, dir);
      for (const glm::dvec3& end : {origin, origin + dir}) {
        const double d = glm::length(toWindow(viewProj * glm::dvec4(end, 1.0), width, height) - centre);
        rayDrift = std::isfinite(d) ? std::max(rayDrift, d) : std::numeric_limits<double>::infinity();
      }
    }
  // An infinite pad bins every triangle to every pixel (everyTriangleACandidate, the tests' reference).
  const double binPad =
      options.everyTriangleACandidate ? std::numeric_limits<double>::infinity() : kBinPad + 2.0 * rayDrift;

  // Edge pass (2D, window space) — also decides which triangles GL would draw as nothing — and
  // the broad phase's bin sizes. Several threads count into one pixel at once.
  std::vector<std::uint8_t> screenDegenerate(triangles.size(), 0);
  std::vector<std::uint32_t> binCounts(pixelCount, 0);
  std::vector<std::uint8_t> inSomeBin(triangles.size(), 0);
  runParallel(threadCount, triangles.size(), 4096, [&](std::size_t t) {
    const WindowPolygon poly = windowPolygon(triangles[t], viewProj, width, height);
    screenDegenerate[t] = polygonArea(poly) < kMinScreenArea ? 1 : 0;
    for (std::size_t i = 0; i < poly.size(); ++i)
      markSegment(poly[i], poly[(i + 1) % poly.size()], options.edgeEpsilon, width, height, region, lists.flags);
    forCandidatePixels(triangles[t], viewProj, width, height, region, binPad, [&](std::size_t pixel) {
      std::atomic_ref<std::uint32_t>(binCounts[pixel]).fetch_add(1, std::memory_order_relaxed);
      inSomeBin[t] = 1;
    });
  });
  // The bins, filled in any order: each ray's hits are sorted by a total order below.
  std::vector<std::uint32_t> binOffsets(pixelCount + 1);
  std::size_t candidateCount = 0;
  for (std::size_t i = 0; i < pixelCount; ++i) {
    binOffsets[i] = static_cast<std::uint32_t>(candidateCount);
    candidateCount += binCounts[i];
    if (candidateCount > UINT32_MAX) throw Error("oracle", "more than 2^32 candidate fragments in one image");
    binCounts[i] = 0;  // from here: the fill cursor
  }
  binOffsets[pixelCount] = static_cast<std::uint32_t>(candidateCount);
  requireHostMemory("oracle", listsOfSize, candidateCount * sizeof(std::uint32_t));
  std::vector<std::uint32_t> bins(candidateCount);
  runParallel(threadCount, triangles.size(), 4096, [&](std::size_t t) {
    if (inSomeBin[t] == 0) return;  // off the region (a probe's one pixel: nearly all of them)
    forCandidatePixels(triangles[t], viewProj, width, height, region, binPad, [&](std::size_t pixel) {
      const std::uint32_t slot =
          std::atomic_ref<std::uint32_t>(binCounts[pixel]).fetch_add(1, std::memory_order_relaxed);
      bins[binOffsets[pixel] + slot] = static_cast<std::uint32_t>(t);
    });
  });

  const glm::vec3 viewDir(camera.forward());
  std::vector<std::vector<Fragment>> rowFragments(static_cast<std::size_t>(height));
  std::vector<std::uint32_t> counts(pixelCount, 0);
  std::vector<std::uint8_t> rayFlags(pixelCount, 0);

  // Where the rays through the next pixel centres right of and above window point (wx, wy) meet
  // the plane of a triangle with this normal; false when one of them runs in the plane (edge-on).
  const auto neighbourPlanePoints = [&](const WorldTriangle& tri, const glm::dvec3& normal, double wx, double wy,
                                        glm::dvec3(&onPlane)[2]) {
    for (int i = 0; i < 2; ++i) {
      glm::dvec3 o, d;
      windowRay(wx + (i == 0 ? 1.0 : 0.0), wy + (i == 1 ? 1.0 : 0.0), o, d);
      const double facing = glm::dot(normal, d);
      if (facing == 0.0) return false;
      onPlane[i] = o + d * (glm::dot(normal, tri.p[0] - o) / facing);
    }
    return true;
  };
  // |∂z/∂x| + |∂z/∂y| of the window depth on the triangle's plane at window point (wx, wy), where
  // the plane's depth is `depth`: window depth is affine in window x and y on a plane, so the
  // differences to the plane's depths one pixel right and one up are exact. Edge-on: 1 (the
  // whole depth range; such pixels are flagged anyway).
  const auto depthSlope = [&](const WorldTriangle& tri, const glm::dvec3& normal, double depth, double wx, double wy) {
    glm::dvec3 onPlane[2];
    if (!neighbourPlanePoints(tri, normal, wx, wy, onPlane)) return 1.0;
    double slope = 0.0;
    for (const glm::dvec3& p : onPlane) {
      const glm::dvec4 clip = viewProj * glm::dvec4(p, 1.0);
      if (!(clip.w != 0.0)) return 1.0;
      slope += std::abs(0.5 * clip.z / clip.w + 0.5 - depth);
    }
    return std::min(slope, 1.0);
  };
  const std::optional<Bounds>& clipBox = scene.clipBox;
  // Whether the line where the triangle's plane meets a face of the clip box passes within
  // edgeEpsilon pixels of the centre whose ray hits that plane at p: each face coordinate's change
  // per pixel on the plane comes from the rays through the next centres right and up. There GL's
  // clipping (in float, then snapped) and the exact test may disagree, like at a triangle's edge.
  const auto nearClipFace = [&](const WorldTriangle& tri, const glm::dvec3& normal, const glm::dvec3& p, double wx,
                                double wy) {
    glm::dvec3 onPlane[2];
    if (!neighbourPlanePoints(tri, normal, wx, wy, onPlane)) return true;  // edge-on: no measure; ambiguous
    for (int a = 0; a < 3; ++a) {
      const double perPixel = std::hypot(onPlane[0][a] - p[a], onPlane[1][a] - p[a]);
      for (const double face : {clipBox->min[a], clipBox->max[a]})
        if (std::abs(p[a] - face) <= options.edgeEpsilon * perPixel) return true;
    }
    return false;
  };

  std::atomic<std::size_t> castBytes{0};
  std::atomic<std::size_t> uncheckedBytes{0};
  const auto castRow = [&](int y, std::vector<Hit>& hits) {
    std::vector<Fragment>& out = rowFragments[static_cast<std::size_t>(y)];
    const double wy = (height - 1 - y) + 0.5;
    for (int x = region.x; x < region.x + region.width; ++x) {
      const std::size_t pixel = static_cast<std::size_t>(y) * width + x;
      glm::dvec3 origin, dir;
      windowRay(x + 0.5, wy, origin, dir);
      const std::span<const std::uint32_t> candidates(bins.data() + binOffsets[pixel],
                                                      bins.data() + binOffsets[pixel + 1]);
      hits.clear();
      for (const std::uint32_t index : candidates) {
        const WorldTriangle& tri = triangles[index];
        double u = 0.0;
        double v = 0.0;
        if (!intersect(origin, dir, tri, u, v)) continue;
        const glm::dvec3 p = tri.p[0] + u * (tri.p[1] - tri.p[0]) + v * (tri.p[2] - tri.p[0]);
        const glm::dvec4 clip = viewProj * glm::dvec4(p, 1.0);
        const double depth = 0.5 * clip.z / clip.w + 0.5;
        if (!(depth >= 0.0 && depth <= 1.0)) continue;
        if (screenDegenerate[index] != 0) {
          rayFlags[pixel] |= FragmentLists::kEdge;
          continue;
        }
        const glm::dvec3 normal = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
        if (clipBox) {
          if (nearClipFace(tri, normal, p, x + 0.5, wy)) rayFlags[pixel] |= FragmentLists::kEdge;
          if (!insideClipBox(clipBox, p)) continue;
        }
        Fragment frag;
        frag.depth = static_cast<float>(depth);
        frag.depthSlope = static_cast<float>(depthSlope(tri, normal, depth, x + 0.5, wy));
        if (!options.countsOnly) frag.color = shade(tri, objects[tri.objectId], u, v, viewDir);
        frag.objectId = tri.objectId;
        frag.frontFacing = glm::dot(normal, dir) < 0.0;
        hits.push_back({depth, tri.objectId, index, frag});
      }
      std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
        if (a.depth != b.depth) return a.depth < b.depth;
        if (a.objectId != b.objectId) return a.objectId < b.objectId;
        return a.triangle < b.triangle;
      });
      for (std::size_t i = 0; i < hits.size(); ++i) {
        if (i > 0 &&
            std::abs(hits[i].depth - hits[i - 1].depth) <
                options.depthTieEpsilon * std::max({1e-30, std::abs(hits[i].depth), std::abs(hits[i - 1].depth)}) +
                    kSubpixelStep * (static_cast<double>(hits[i].fragment.depthSlope) +
                                     static_cast<double>(hits[i - 1].fragment.depthSlope)))
          rayFlags[pixel] |= FragmentLists::kDepthTie;
        if (!options.countsOnly) out.push_back(hits[i].fragment);
      }
      counts[pixel] = static_cast<std::uint32_t>(hits.size());
    }
    // Every 64 MiB of rows, ask whether the lists cast so far could still be copied into one
    // array at the end (below); if not, stop now rather than after casting the rest.
    out.shrink_to_fit();  // growth left up to twice the row's fragments allocated
    constexpr std::size_t kCheckEvery = std::size_t{64} << 20;
    const std::size_t rowBytes = out.size() * sizeof(Fragment);
    const std::size_t cast = castBytes.fetch_add(rowBytes) + rowBytes;
    if (uncheckedBytes.fetch_add(rowBytes) + rowBytes >= kCheckEvery) {
      uncheckedBytes = 0;
      requireHostMemory("oracle", listsOfSize, cast);
    }
  };

  runParallel(std::min(threadCount, static_cast<unsigned>(region.height)), static_cast<std::size_t>(region.height), 1,
              [&](std::size_t row) {
                thread_local std::vector<Hit> hits;
                castRow(region.y + static_cast<int>(row), hits);
              });

  lists.offsets.resize(pixelCount + 1);
  std::size_t total = 0;
  for (std::size_t i = 0; i < pixelCount; ++i) {
    lists.offsets[i] = static_cast<std::uint32_t>(total);
    total += counts[i];
    lists.flags[i] |= rayFlags[i];
  }
  if (total > UINT32_MAX) throw Error("oracle", "more than 2^32 fragments in one image");
  lists.offsets[pixelCount] = static_cast<std::uint32_t>(total);
  if (options.countsOnly) return lists;
  requireHostMemory("oracle", listsOfSize, total * sizeof(Fragment));
  lists.fragments.reserve(total);
  for (std::vector<Fragment>& row : rowFragments) {
    lists.fragments.insert(lists.fragments.end(), row.begin(), row.end());
    std::vector<Fragment>().swap(row);
  }
  return lists;
}

}  // namespace mfr
