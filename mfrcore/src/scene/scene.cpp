#include "mfr/scene/scene.hpp"

#include <algorithm>
#include <cmath>

#include "mfr/error.hpp"

namespace mfr {

Bounds Scene::bounds() const {
  Bounds b;
  for (const Object& o : objects) {
    if (!o.visible || !o.mesh) continue;
    const Bounds mb = o.mesh->bounds();
    if (!mb.valid()) continue;
    // Transform the 8 corners: exact enough for framing and depth range.
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 corner((i & 1) ? mb.max.x : mb.min.x, (i & 2) ? mb.max.y : mb.min.y,
                              (i & 4) ? mb.max.z : mb.min.z);
      b.extend(glm::dvec3(o.transform * glm::dvec4(corner, 1.0)));
    }
  }
  return b;
}

double Scene::boundingRadius() const {
  const glm::dvec3 c = bounds().center();
  double r2 = 0.0;
  for (const Object& o : objects) {
    if (!o.visible || !o.mesh) continue;
    for (const glm::vec3& p : o.mesh->positions) {
      const glm::dvec3 d = glm::dvec3(o.transform * glm::dvec4(glm::dvec3(p), 1.0)) - c;
      r2 = std::max(r2, glm::dot(d, d));
    }
  }
  return std::sqrt(r2);
}

Camera Scene::fit(const Camera& base) const { return base.fittedTo(bounds(), boundingRadius()); }

std::size_t Scene::triangleCount() const {
  std::size_t n = 0;
  for (const Object& o : objects)
    if (o.visible && o.mesh) n += o.mesh->triangleCount();
  return n;
}

void Scene::validate() const {
  if (triangleCount() == 0) throw Error("scene '" + name + "'", "nothing to render (no visible triangles)");
}

std::vector<std::string> Scene::viewNames() const {
  std::vector<std::string> names{"fit"};
  for (const NamedView& v : views) names.push_back(v.name);
  return names;
}

Camera Scene::view(const std::string& viewName) const {
  for (const NamedView& v : views)
    if (v.name == viewName) return v.camera;
  if (viewName.empty() || viewName == "fit") {
    // Fit-all keeps the direction of the first named view, else looks down -Z from +Z.
    Camera base = views.empty() ? Camera{} : views.front().camera;
    return fit(base);
  }
  std::string list;
  for (const std::string& n : viewNames()) list += (list.empty() ? "" : ", ") + n;
  throw Error("view '" + viewName + "'", "not in scene '" + name + "' (available: " + list + ")");
}

}  // namespace mfr
