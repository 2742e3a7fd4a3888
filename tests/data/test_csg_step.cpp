// Image-space CSG on a real CAD part: the linkrods STEP file of Open CASCADE's samples (Debian
// occt-misc, shared/DATA.md), triangulated by our STEP loader, cut by and joined with a sphere,
// against CGAL's exact Booleans of the same meshes (tests/support/csg_reference.hpp), and the GPU
// against the oracle on it.
#include <gtest/gtest.h>

#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "csg_reference.hpp"
#include "gl_fixture.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/primitives.hpp"

namespace mfr::test {
namespace {

constexpr const char* kLinkrods = "/usr/share/opencascade/data/step/linkrods.step";
constexpr double kScale = 0.95;

// The part, centred and scaled into the reference views (bounds [3.1, 8.1] × [2.5, 4] × [0, 2]),
// and a sphere over the middle of both rods.
Scene linkrodsAndBall(CsgNode::Op op) {
  EXPECT_TRUE(std::filesystem::exists(kLinkrods)) << "test data missing: run scripts/setup";
  Scene part = loadScene(kLinkrods);
  EXPECT_EQ(part.objects.size(), 1u);
  Scene s;
  s.name = "linkrods";
  csg::addObject(
      s, "rods", Mesh(*part.objects[0].mesh),
      glm::scale(glm::dmat4(1.0), glm::dvec3(kScale)) * glm::translate(glm::dmat4(1.0), -glm::dvec3(5.635, 3.25, 1.0)),
      {0.0f, 0.45f, 0.7f, 1.0f});
  // The sphere of radius 1.2 at (5.6, 3.2, 1.6) in the file's coordinates.
  csg::addObject(s, "ball", makeSphere(1.2 * kScale, 48, 24),
                 glm::translate(glm::dmat4(1.0), kScale * glm::dvec3(-0.035, -0.05, 0.6)), {0.9f, 0.3f, 0.3f, 1.0f});
  validateCsg(s);  // the STEP triangulation must be a closed surface
  const auto primitive = [](std::uint32_t object) { return CsgNode{CsgNode::Op::Primitive, object, {}}; };
  s.csg.root = CsgNode{op, 0, {primitive(0), primitive(1)}};
  validateCsg(s);
  return s;
}

TEST(CsgStep, LinkrodsAgainstCgal) {
  for (const auto& [op, boolean] : {std::pair{CsgNode::Op::Difference, csg::Boolean::Difference},
                                    std::pair{CsgNode::Op::Union, csg::Boolean::Union},
                                    std::pair{CsgNode::Op::Intersection, csg::Boolean::Intersection}}) {
    const Scene scene = linkrodsAndBall(op);
    SCOPED_TRACE(static_cast<int>(op));
    const csg::SurfaceMesh solid = csg::boolean(boolean, csg::toCgal(scene.objects[0]), csg::toCgal(scene.objects[1]));
    // About 3/4 of the surface pixels measured in the view with fewer (1267, 2080, 395).
    const int minHits = op == CsgNode::Op::Difference ? 950 : op == CsgNode::Op::Union ? 1560 : 290;
    csg::compareBothViews(scene, csg::referenceScene(scene.name, solid), minHits);
  }
}

TEST(CsgStep, LinkrodsGpuEqualsOracle) {
  context();
  const Scene scene = linkrodsAndBall(CsgNode::Op::Difference);
  const Camera camera = csg::perspectiveView();
  const int w = 160, h = 120;
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  const ImageRGBA8 expected = compositeCsg(oracle, scene);
  GpuRenderer gpu;
  gpu.setScene(scene);
  for (const char* method : {"abuffer-ll", "abuffer-sbuffer"}) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.operation = "csg";
    req.width = w;
    req.height = h;
    const ImageComparison c = compareImages(oracle, expected, gpu.render(camera, req).image, 2);
    EXPECT_GT(c.compared, static_cast<std::size_t>(w * h) * 8 / 10);
    EXPECT_GE(c.fraction(), 0.999) << (c.compared - c.within) << " of " << c.compared << " pixels off";
  }
}

}  // namespace
}  // namespace mfr::test
