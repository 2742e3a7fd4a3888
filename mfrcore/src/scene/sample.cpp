#include "mfr/scene/sample.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

#include "mfr/error.hpp"
#include "mfr/scene/primitives.hpp"

namespace mfr {
namespace {
// Adds a generated part to a built-in scene.
void addPart(Scene& s, const std::string& name, Mesh mesh, const glm::vec4& color, const glm::dmat4& xf) {
  Object o;
  o.name = name;
  o.mesh = std::make_shared<const Mesh>(std::move(mesh));
  o.material.color = color;
  o.transform = xf;
  s.objects.push_back(std::move(o));
}
}  // namespace

Scene makeSampleScene() {
  Scene s;
  s.name = "sample";
  s.background = glm::vec3(1.0f);
  const auto add = [&](const std::string& name, Mesh mesh, const glm::vec4& color,
                       const glm::dmat4& xf = glm::dmat4(1.0)) { addPart(s, name, std::move(mesh), color, xf); };
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

Scene makeCsgSampleScene() {
  Scene s;
  s.name = "csg";
  s.background = glm::vec3(1.0f);
  const auto add = [&](const std::string& name, Mesh mesh, const glm::vec4& color, const glm::dmat4& xf) {
    addPart(s, name, std::move(mesh), color, xf);
  };
  const glm::dmat4 id(1.0);
  add("block", makeBox({2.0, 1.4, 2.0}), {0.70f, 0.72f, 0.78f, 1.0f}, id);
  add("ball", makeSphere(1.32, 96, 48), {0.95f, 0.70f, 0.35f, 1.0f}, id);
  // Drills longer than the block, so no cap is coplanar with a face (coincident faces are undefined).
  add("drill x", makeCylinder(0.38, 3.0, 64), {0.90f, 0.30f, 0.30f, 1.0f},
      glm::rotate(id, glm::radians(90.0), glm::dvec3(0, 0, 1)));
  add("drill z", makeCylinder(0.25, 3.0, 64), {0.30f, 0.45f, 0.90f, 1.0f},
      glm::translate(id, glm::dvec3(0.45, 0.2, 0.0)) * glm::rotate(id, glm::radians(90.0), glm::dvec3(1, 0, 0)));
  const auto primitive = [](std::uint32_t object) { return CsgNode{CsgNode::Op::Primitive, object, {}}; };
  CsgNode rounded{CsgNode::Op::Intersection, 0, {primitive(0), primitive(1)}};
  s.csg.root = CsgNode{CsgNode::Op::Difference, 0, {rounded, primitive(2), primitive(3)}};

  Camera iso;
  iso.eye = {3.1, 2.3, 3.7};
  iso.target = {0.0, 0.0, 0.0};
  iso.fovyDegrees = 35.0;
  s.views.push_back({"iso", s.fit(iso)});
  Camera front = iso;
  front.eye = {0.3, 0.25, 4.0};
  s.views.push_back({"front", s.fit(front)});
  return s;
}

Scene makeIntersectingSampleScene() {
  Scene s;
  s.name = "intersect";
  s.background = glm::vec3(1.0f);
  const glm::dmat4 id(1.0);
  // Two versions of one surface a few hundredths apart (a design and its scan): they cross each
  // other along curves, where "over" cuts hard edges and z-thickness blends.
  addPart(s, "design", makeSphere(1.0, 96, 48), {0.25f, 0.45f, 0.90f, 0.45f}, id);
  addPart(s, "scan", makeSphere(0.99, 96, 48), {0.95f, 0.55f, 0.15f, 0.45f},
          glm::translate(id, glm::dvec3(0.045, 0.03, 0.02)) * glm::scale(id, glm::dvec3(1.0, 1.04, 0.98)));
  // A plate imported twice (a duplicated CAD part, different colours): coincident faces.
  const Mesh plate = makeBox({2.8, 0.1, 1.8});
  const glm::dmat4 below = glm::translate(id, glm::dvec3(0.0, -1.25, 0.0));
  addPart(s, "plate", plate, {0.55f, 0.57f, 0.60f, 0.7f}, below);
  addPart(s, "plate (copy)", plate, {0.20f, 0.65f, 0.30f, 0.7f}, below);
  // A ring through the plate: surfaces crossing at a steep angle.
  addPart(s, "ring", makeTorus(0.45, 0.08, 96, 24), {0.80f, 0.20f, 0.45f, 0.8f},
          glm::translate(id, glm::dvec3(0.9, -1.25, 0.3)) * glm::rotate(id, glm::radians(90.0), glm::dvec3(1, 0, 0)));
  Camera iso;
  iso.eye = {2.6, 1.6, 4.4};
  iso.target = {0.0, -0.4, 0.0};
  iso.fovyDegrees = 35.0;
  s.views.push_back({"iso", s.fit(iso)});
  Camera front = iso;
  front.eye = {0.0, -0.2, 5.0};
  front.target = {0.0, -0.2, 0.0};
  s.views.push_back({"front", s.fit(front)});
  return s;
}

Scene makeVolumeSampleScene() {
  Scene s;
  s.name = "volume";
  s.background = glm::vec3(1.0f);
  // The field on [-1, 1]³: a dense Gaussian core, a hollow shell at radius 0.75 and six blobs on
  // a ring of radius 0.5 in the xz-plane. Values in [0, ~1].
  constexpr int n = 96;
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = glm::ivec3(n);
  grid->values.resize(static_cast<std::size_t>(n) * n * n);
  const double h = 2.0 / (n - 1);
  std::size_t at = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const glm::dvec3 p(-1.0 + i * h, -1.0 + j * h, -1.0 + k * h);
        const double r = glm::length(p);
        double v = std::exp(-r * r / (2 * 0.24 * 0.24)) + 0.4 * std::exp(-(r - 0.75) * (r - 0.75) / (2 * 0.05 * 0.05));
        for (int b = 0; b < 6; ++b) {
          const double a = b * 3.14159265358979 / 3.0;
          const glm::dvec3 c(0.5 * std::cos(a), 0.0, 0.5 * std::sin(a));
          const double d2 = glm::dot(p - c, p - c);
          v += 0.85 * std::exp(-d2 / (2 * 0.11 * 0.11));
        }
        grid->values[at++] = static_cast<float>(v);
      }
  Volume vol;
  vol.name = "field";
  vol.grid = std::move(grid);
  vol.origin = glm::dvec3(-1.0);
  vol.spacing = glm::dvec3(h);
  vol.transfer.unitDistance = 0.1;
  vol.transfer.points = {{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},     {0.15, {0.20f, 0.40f, 0.90f, 0.0f}},
                         {0.4, {0.25f, 0.55f, 0.95f, 0.12f}}, {0.6, {0.30f, 0.85f, 0.55f, 0.3f}},
                         {0.8, {1.00f, 0.70f, 0.15f, 0.6f}},  {1.0, {0.90f, 0.15f, 0.25f, 0.95f}}};
  s.volumes.push_back(std::move(vol));

  const glm::dmat4 id(1.0);
  addPart(s, "plate", makeBox({2.6, 0.04, 2.6}), {0.55f, 0.60f, 0.70f, 0.35f},
          glm::translate(id, glm::dvec3(0.0, -0.1, 0.0)));
  addPart(s, "rod", makeCylinder(0.06, 2.6), {0.85f, 0.15f, 0.20f, 0.8f},
          glm::rotate(id, glm::radians(90.0), glm::dvec3(0, 0, 1)) *
              glm::rotate(id, glm::radians(25.0), glm::dvec3(1, 0, 0)));
  addPart(s, "sphere", makeSphere(0.4, 64, 32), {0.95f, 0.85f, 0.30f, 0.5f},
          glm::translate(id, glm::dvec3(0.9, 0.5, 0.3)));
  Camera iso;
  iso.eye = {2.6, 1.8, 3.6};
  iso.target = {0.0, 0.0, 0.0};
  iso.fovyDegrees = 35.0;
  s.views.push_back({"iso", s.fit(iso)});
  Camera front = iso;
  front.eye = {0.3, 0.2, 5.0};
  s.views.push_back({"front", s.fit(front)});
  return s;
}

Scene makeQuadsScene(int layers, double density, std::uint32_t seed) {
  if (layers < 1 || layers > 4096) throw Error("@quads", "layer count must be in [1, 4096]");
  if (!(density > 0.0) || density > 1.0) throw Error("@quads", "pixel density must be in (0, 1]");
  Scene s;
  s.name = "quads-" + std::to_string(layers);
  s.background = glm::vec3(1.0f);
  // Same deterministic generator as the primitives (splitmix-style), so runs are comparable.
  std::uint32_t state = seed * 2654435761u + 0x9E3779B9u;
  const auto uniform = [&state] {
    std::uint32_t z = (state += 0x9E3779B9u);
    z = (z ^ (z >> 16)) * 0x85EBCA6Bu;
    z = (z ^ (z >> 13)) * 0xC2B2AE35u;
    z ^= z >> 16;
    return z / 4294967296.0;
  };
  const double side = 2.0 * std::sqrt(density);  // the view is 2 × 2 world units
  // Four triangles fanned from an off-centre interior point: the two diagonals of a two-triangle
  // quad would run exactly through pixel centres of a square image, where the oracle's tie rule
  // and the rasteriser's may pick different triangles (the same surface, a colour's rounding apart).
  auto quad = std::make_shared<const Mesh>([side] {
    Mesh m;
    const float h = static_cast<float>(side / 2);
    m.positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}, {0.1234567f * h, 0.0456789f * h, 0}};
    m.normals.assign(5, glm::vec3(0, 0, 1));
    m.indices = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
    return m;
  }());
  for (int i = 0; i < layers; ++i) {
    Object o;
    o.name = "quad " + std::to_string(i);
    o.mesh = quad;
    // Depths spread over (−0.95, 0.95) in strata with jitter: random order, no exact ties.
    const double z = -0.95 + 1.9 * (i + 0.1 + 0.8 * uniform()) / layers;
    o.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, z));
    o.material.color =
        glm::vec4(0.2f + 0.8f * static_cast<float>(uniform()), 0.2f + 0.8f * static_cast<float>(uniform()),
                  0.2f + 0.8f * static_cast<float>(uniform()), 0.15f + 0.35f * static_cast<float>(uniform()));
    s.objects.push_back(std::move(o));
  }
  // Draw order must not follow depth order: shuffle (Fisher–Yates with the same generator).
  for (std::size_t i = s.objects.size(); i > 1; --i)
    std::swap(s.objects[i - 1], s.objects[static_cast<std::size_t>(uniform() * static_cast<double>(i))]);
  Camera c;
  c.projection = Projection::Orthographic;
  c.eye = {0.0, 0.0, 2.0};
  c.target = {0.0, 0.0, 0.0};
  c.orthoHeight = 2.0;
  c.nearPlane = 0.5;
  c.farPlane = 3.5;
  s.views.push_back({"front", c});
  return s;
}

}  // namespace mfr
