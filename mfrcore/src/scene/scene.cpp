#include "mfr/scene/scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <glm/trigonometric.hpp>

#include "mfr/error.hpp"
#include "mfr/list_text.hpp"
#include "mfr/scene/clip_box.hpp"
#include "number_text.hpp"

namespace mfr {

Bounds Scene::bounds() const {
  if (uncutExtent) return uncutExtent->first;
  Bounds b;
  for (const Object& o : objects) {
    if (!o.visible || !o.mesh) continue;
    const Bounds mb = o.mesh->bounds();
    if (!mb.valid()) continue;
    // Transform the 8 corners: exact enough for framing and depth range.
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 corner = mb.corner(i);
      b.extend(glm::dvec3(o.transform * glm::dvec4(corner, 1.0)));
    }
  }
  for (const Volume& v : volumes)
    if (v.visible) b.extend(v.bounds());
  return b;
}

double Scene::boundingRadius() const {
  if (uncutExtent) return uncutExtent->second;
  const glm::dvec3 c = bounds().center();
  double r2 = 0.0;
  for (const Object& o : objects) {
    if (!o.visible || !o.mesh) continue;
    for (const glm::vec3& p : o.mesh->positions) {
      const glm::dvec3 d = glm::dvec3(o.transform * glm::dvec4(glm::dvec3(p), 1.0)) - c;
      r2 = std::max(r2, glm::dot(d, d));
    }
  }
  for (const Volume& v : volumes) {
    if (!v.visible || !v.grid) continue;
    const glm::dmat4 toWorld = v.gridToWorld();
    const glm::dvec3 last(v.grid->dims - 1);
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 corner((i & 1) ? last.x : 0.0, (i & 2) ? last.y : 0.0, (i & 4) ? last.z : 0.0);
      const glm::dvec3 d = glm::dvec3(toWorld * glm::dvec4(corner, 1.0)) - c;
      r2 = std::max(r2, glm::dot(d, d));
    }
  }
  return std::sqrt(r2);
}

Camera Scene::fit(const Camera& base) const {
  return base.fittedTo(bounds(), boundingRadius());
}

std::size_t Scene::triangleCount() const {
  std::size_t n = 0;
  for (const Object& o : objects)
    if (o.visible && o.mesh) n += o.mesh->triangleCount();
  return n;
}

std::vector<Volume> Scene::visibleVolumes() const {
  std::vector<Volume> out;
  for (const Volume& v : volumes)
    if (v.visible) out.push_back(v);
  return out;
}

bool Scene::hasVisibleVolume() const {
  return std::any_of(volumes.begin(), volumes.end(), [](const Volume& v) { return v.visible; });
}

void Scene::validate() const {
  std::size_t visibleVolumes = 0;
  for (const Volume& v : volumes) {
    v.validate();
    visibleVolumes += v.visible ? 1 : 0;
  }
  if (triangleCount() == 0 && visibleVolumes == 0)
    throw Error("scene '" + name + "'", "nothing to render (no visible triangles or volume)");
  if (visibleVolumes > kMaxVisibleVolumes)
    throw Error("scene '" + name + "'", std::to_string(visibleVolumes) + " visible volumes: at most " +
                                            std::to_string(kMaxVisibleVolumes) + " can be drawn at once");
  // Where single precision draws it: within ±1e15, as a scene file's coordinates and volumes, and
  // not below 1e-30 across (0 across: every triangle degenerate, which checkDrawable names). A
  // model file's triangle at 1e31 was drawn as a sliver and at 1e33 or 1e-38 not at all by the GPU,
  // with exit 0, while the oracle drew them (a bug hunt).
  const Bounds extent = bounds();
  if (extent.valid()) {
    for (int a = 0; a < 3; ++a)
      if (!(std::abs(extent.min[a]) <= 1e15 && std::abs(extent.max[a]) <= 1e15))
        throw Error("scene '" + name + "'",
                    "reaches beyond ±1e15 (to " +
                        shortNumberText(std::max(std::abs(extent.min[a]), std::abs(extent.max[a]))) +
                        "): too far out to be drawn in single precision");
    if (const double across = glm::length(extent.max - extent.min); across > 0.0 && across < 1e-30)
      throw Error("scene '" + name + "'",
                  "is " + shortNumberText(across) + " across, below 1e-30: too small to be drawn in single precision");
  }
  validateCsg(*this);
  validateClipBox(clipBox, "clip box");
  validateSectionPlane(section, "section plane");
}

void validateSectionPlane(const std::optional<SectionPlane>& plane, const std::string& what) {
  if (!plane) return;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(plane->point[a]) || !std::isfinite(plane->normal[a]))
      throw Error(what, "needs a finite point and normal");
  const double length = glm::length(plane->normal);
  if (!(length > 1e-12) || !std::isfinite(length)) throw Error(what, "needs a non-zero normal of finite length");
}

void validateClipBox(const std::optional<Bounds>& box, const std::string& what) {
  if (!box) return;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(box->min[a]) || !std::isfinite(box->max[a]) || !(box->min[a] <= box->max[a]))
      throw Error(what, "needs finite corners with min <= max on every axis");
}

bool insideClipBox(const std::optional<Bounds>& box, const glm::dvec3& p) {
  return !box || (p.x >= box->min.x && p.y >= box->min.y && p.z >= box->min.z && p.x <= box->max.x &&
                  p.y <= box->max.y && p.z <= box->max.z);
}

std::vector<std::string> Scene::viewNames() const {
  std::vector<std::string> names{"fit"};
  for (const NamedView& v : views) names.push_back(v.name);
  for (const char* standard : {"front", "iso"})
    if (std::find(names.begin(), names.end(), standard) == names.end()) names.emplace_back(standard);
  return names;
}

std::optional<Camera> Scene::standardView(const std::string& viewName) const {
  if (viewName != "front" && viewName != "iso") return std::nullopt;
  Camera base;
  base.eye = viewName == "front" ? glm::dvec3(0.0, 0.0, 1.0) : glm::dvec3(1.0, 0.8, 1.0);
  base.target = glm::dvec3(0.0);
  return fit(base);
}

Camera Scene::view(const std::string& viewName) const {
  for (const NamedView& v : views)
    if (v.name == viewName) return v.camera;
  // Commands whose default view is "iso" (evaluate, dataset, allocations) work on every scene.
  if (const std::optional<Camera> standard = standardView(viewName)) return *standard;
  if (viewName.rfind("orbit:", 0) == 0) {
    // orbit:AZIMUTH:ELEVATION (degrees): a fit-all view from that direction, +Y up; azimuth 0
    // looks from +Z, 90 from +X.
    double azimuth = 0, elevation = 0;
    char extra = 0;
    // sscanf's %lf skips blanks: "orbit: 5:0" was taken (a bug hunt), as other views' names are not.
    const bool blank = std::any_of(viewName.begin(), viewName.end(), [](unsigned char c) { return std::isspace(c); });
    if (blank || std::sscanf(viewName.c_str(), "orbit:%lf:%lf%c", &azimuth, &elevation, &extra) != 2 ||
        !std::isfinite(azimuth) || !std::isfinite(elevation) || std::abs(elevation) > 89.0)
      throw Error("view '" + viewName + "'", "expected orbit:AZIMUTH:ELEVATION in degrees, |elevation| <= 89");
    const double az = glm::radians(azimuth), el = glm::radians(elevation);
    Camera base;
    base.target = glm::dvec3(0.0);
    base.eye = glm::dvec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    base.up = {0.0, 1.0, 0.0};
    return fit(base);
  }
  if (viewName.empty() || viewName == "fit") {
    // Fit-all keeps the direction of the first named view, else looks down -Z from +Z.
    Camera base = views.empty() ? Camera{} : views.front().camera;
    return fit(base);
  }
  std::string list;
  for (const std::string& n : viewNames()) list += (list.empty() ? "" : ", ") + n;
  throw Error("view '" + viewName + "'",
              "not in scene '" + name + "' (available: " + list + ", or orbit:AZIMUTH:ELEVATION)");
}

void requireClipBoxHoldsScene(const Scene& scene, const Bounds& box, const std::string& what) {
  const Bounds b = scene.bounds();
  bool holds = b.valid();
  // An axis on which the scene itself is flat (a plane, one slice of a volume) is held by a box
  // that covers it, even a flat one: the viewer's Clip dock starts at the scene's bounds, and
  // refused them on such a scene (a review).
  for (int a = 0; a < 3; ++a)
    holds = holds && ((box.max[a] > box.min[a] && box.min[a] < b.max[a] && box.max[a] > b.min[a]) ||
                      (b.max[a] == b.min[a] && box.min[a] <= b.min[a] && box.max[a] >= b.max[a]));
  if (holds) return;
  std::ostringstream bounds;
  bounds << "[" << b.min.x << ", " << b.min.y << ", " << b.min.z << "] – [" << b.max.x << ", " << b.max.y << ", "
         << b.max.z << "]";
  throw Error(
      what, "holds nothing of scene '" + scene.name + "' (a flat box, or one outside its bounds " + bounds.str() + ")");
}

void requireSomethingToDraw(const Scene& scene) {
  if (!scene.clipBox && !scene.section) return;  // Scene::validate refuses a scene with nothing at all
  const std::optional<Bounds>& clip = scene.clipBox;
  const auto meetsClip = [&clip](const Bounds& b) {
    for (int a = 0; clip && a < 3; ++a)
      if (b.max[a] < clip->min[a] || b.min[a] > clip->max[a]) return false;
    return true;
  };
  // Triangles: the section has cut them already (sectionedScene), so any left inside the box draws.
  for (const Object& o : scene.objects) {
    if (!o.visible || !o.mesh) continue;
    const Mesh& m = *o.mesh;
    for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      Bounds b;
      for (std::size_t k = 0; k < 3; ++k)
        b.extend(glm::dvec3(o.transform * glm::dvec4(glm::dvec3(m.positions[m.indices[t + k]]), 1.0)));
      if (meetsClip(b)) return;
    }
  }
  // Volumes are cropped at render time: by the box, and to the side the plane's normal points to.
  for (const Volume& v : scene.volumes) {
    if (!v.visible || !v.grid) continue;
    Bounds b = v.bounds();
    if (!meetsClip(b)) continue;
    if (clip) {
      b.min = glm::max(b.min, clip->min);
      b.max = glm::min(b.max, clip->max);
    }
    if (!scene.section) return;
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 corner = b.corner(c);
      if (glm::dot(scene.section->normal, corner - scene.section->point) > 0.0) return;
    }
  }
  const std::string where = scene.clipBox && scene.section ? "inside the clip box on the kept side of the section plane"
                            : scene.clipBox                ? "inside the clip box"
                                                           : "on the kept side of the section plane";
  throw Error("scene '" + scene.name + "'", "nothing to draw " + where);
}

void requireClipBoxInFloatRange(const Bounds& box, const std::string& what) {
  for (int a = 0; a < 3; ++a)
    for (const double v : {box.min[a], box.max[a]})
      if (!(std::abs(v) <= static_cast<double>(std::numeric_limits<float>::max())))
        throw Error(what, "a corner lies beyond a float's range (±3.4e38)");
}

Bounds parseClipBox(const std::string& text, const std::string& what) {
  const auto corners = text::parseTwoVectors<glm::dvec3>(text);
  if (!corners) throw Error(what, "expected six numbers xmin,ymin,zmin,xmax,ymax,zmax (or none)");
  Bounds box;
  box.min = corners->first;
  box.max = corners->second;
  if (!box.valid()) throw Error(what, "min must not exceed max on any axis");
  requireClipBoxInFloatRange(box, what);
  return box;
}

glm::dmat3 normalMatrix(const glm::dmat4& transform) {
  const glm::dmat3 m = glm::transpose(glm::inverse(glm::dmat3(transform)));
  double largest = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) largest = std::max(largest, std::abs(m[c][r]));
  // By a power of two (exact in float), and only far from 1: a transform of ordinary scale keeps its
  // normals bit for bit, and with them the 8-bit rounding ties of CAD colours that tail runs compare
  // (dividing a rotation by its largest entry broke 6 runs on the machine parts).
  if (!(largest > 0.0) || !std::isfinite(largest)) return m;
  const int exponent = std::ilogb(largest);
  return exponent < -20 || exponent > 20 ? m * std::ldexp(1.0, -exponent) : m;
}

}  // namespace mfr
