#include "mfr/scene/sample.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include "mfr/scene/primitives.hpp"

namespace mfr {

Scene makeSampleScene() {
  Scene s;
  s.name = "sample";
  s.background = glm::vec3(1.0f);
  const auto add = [&](const std::string& name, Mesh mesh, const glm::vec4& color, const glm::dmat4& xf = glm::dmat4(1.0)) {
    Object o;
    o.name = name;
    o.mesh = std::make_shared<const Mesh>(std::move(mesh));
    o.material.color = color;
    o.transform = xf;
    s.objects.push_back(std::move(o));
  };
  // Three nested shells (6 layers), two interlocking tori crossing them, and a tangle of tubes
  // inside: a ray through the centre meets 20–40 surfaces — the kind of depth complexity that
  // separates exact from approximate methods.
  add("outer shell", makeSphere(1.0, 64, 32), {0.55f, 0.70f, 0.95f, 0.25f});
  add("middle shell", makeSphere(0.8, 64, 32), {0.95f, 0.75f, 0.35f, 0.30f});
  add("inner shell", makeSphere(0.6, 64, 32), {0.45f, 0.85f, 0.55f, 0.35f});
  add("ring A", makeTorus(0.7, 0.08, 96, 24), {0.90f, 0.30f, 0.30f, 0.55f},
      glm::rotate(glm::dmat4(1.0), glm::radians(60.0), glm::dvec3(1, 0, 0)));
  add("ring B", makeTorus(0.7, 0.08, 96, 24), {0.30f, 0.40f, 0.90f, 0.55f},
      glm::rotate(glm::dmat4(1.0), glm::radians(-60.0), glm::dvec3(0, 1, 0)));
  add("tangle", makeHairball(24, 0.55, 0.025, 7, 96, 10), {0.85f, 0.45f, 0.85f, 0.40f});

  Camera front;
  // Slightly off-axis: a view exactly down an axis puts the spheres' quad diagonals on pixel
  // centres, where rasterisation tie rules (not the methods) decide.
  front.eye = {0.35, 0.25, 4.0};
  front.target = {0.0, 0.0, 0.0};
  front.fovyDegrees = 35.0;
  s.views.push_back({"front", s.fit(front)});
  Camera iso = front;
  iso.eye = {2.5, 2.0, 2.5};
  s.views.push_back({"iso", s.fit(iso)});
  return s;
}

}  // namespace mfr
