// Surface measures (scene/measure.hpp) against closed forms: a box's area and volume under a
// scaling, mirroring and translating placement; a sphere's and a torus's inscribed polyhedra
// (their exact area and volume from the vertices: each is a sum of known triangles/tetrahedra,
// so the closed form of the smooth shape bounds them); and the topology that decides whether a
// volume is reported: holes, non-manifold edges and triangles wound against their neighbours.
#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "mfr/scene/measure.hpp"
#include "mfr/scene/primitives.hpp"

namespace mfr::test {
namespace {

TEST(SurfaceMeasure, BoxUnderAPlacementHasItsAreaAndVolume) {
  const Mesh box = makeBox(glm::dvec3(1.0));  // faces with vertices of their own (split by normals)
  ASSERT_GT(box.positions.size(), 8u);
  const glm::dmat4 place = glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(5.0, -3.0, 2.0)), glm::dvec3(2, 3, 4));
  const SurfaceMeasures m = measureSurface(box, place);
  EXPECT_TRUE(m.closed());
  EXPECT_EQ(m.boundaryEdges, 0u);
  EXPECT_NEAR(m.area, 2.0 * (2 * 3 + 2 * 4 + 3 * 4), 1e-9);
  EXPECT_NEAR(m.volume, 24.0, 1e-9);  // the translation does not change it
  // Nor does one far from the origin: summed about the origin, the tetrahedra's large terms
  // cancelled, and a box at 10⁸ measured 4·10⁸ (a bug hunt).
  for (const double far : {1e8, 1e12, -5.4e6}) {
    SCOPED_TRACE(far);
    const SurfaceMeasures away = measureSurface(box, glm::translate(place, glm::dvec3(far, far, 0.5 * far)));
    EXPECT_NEAR(away.volume, 24.0, 1e-9);
    EXPECT_NEAR(away.area, m.area, 1e-9);
  }
  // A mirror keeps the part's own sign.
  const SurfaceMeasures mirrored = measureSurface(box, glm::scale(glm::dmat4(1.0), glm::dvec3(-1, 1, 1)));
  EXPECT_TRUE(mirrored.closed());
  EXPECT_NEAR(mirrored.volume, 1.0, 1e-9);
  // Inside out: every triangle reversed.
  Mesh inverted = box;
  for (std::size_t t = 0; t < inverted.indices.size(); t += 3)
    std::swap(inverted.indices[t + 1], inverted.indices[t + 2]);
  const SurfaceMeasures in = measureSurface(inverted, glm::dmat4(1.0));
  EXPECT_TRUE(in.closed());
  EXPECT_NEAR(in.volume, -1.0, 1e-9);
}

TEST(SurfaceMeasure, TessellatedSphereAndTorusLieBetweenTheirBounds) {
  // Inscribed polyhedra: below the smooth shape's area and volume, and close to them.
  const double r = 2.0, pi = glm::pi<double>();
  const SurfaceMeasures s = measureSurface(makeSphere(r, 96, 48), glm::dmat4(1.0));
  EXPECT_TRUE(s.closed()) << s.boundaryEdges << " boundary, " << s.nonManifoldEdges << " non-manifold";
  EXPECT_LT(s.volume, 4.0 / 3.0 * pi * r * r * r);
  EXPECT_GT(s.volume, 0.995 * 4.0 / 3.0 * pi * r * r * r);
  EXPECT_LT(s.area, 4.0 * pi * r * r);
  EXPECT_GT(s.area, 0.995 * 4.0 * pi * r * r);
  const double R = 3.0, a = 1.0;
  const SurfaceMeasures t = measureSurface(makeTorus(R, a, 128, 48), glm::dmat4(1.0));
  EXPECT_TRUE(t.closed());
  EXPECT_NEAR(t.volume, 2.0 * pi * pi * R * a * a, 0.005 * 2.0 * pi * pi * R * a * a);
  EXPECT_NEAR(t.area, 4.0 * pi * pi * R * a, 0.005 * 4.0 * pi * pi * R * a);
}

TEST(SurfaceMeasure, HolesNonManifoldEdgesAndFlippedTrianglesAreNotClosed) {
  const Mesh box = makeBox(glm::dvec3(1.0));
  Mesh holed = box;
  holed.indices.resize(holed.indices.size() - 3);  // one triangle less: a hole of three edges
  const SurfaceMeasures h = measureSurface(holed, glm::dmat4(1.0));
  EXPECT_FALSE(h.closed());
  EXPECT_EQ(h.boundaryEdges, 3u);

  Mesh flipped = box;
  std::swap(flipped.indices[1], flipped.indices[2]);  // one triangle wound against its neighbours
  const SurfaceMeasures f = measureSurface(flipped, glm::dmat4(1.0));
  EXPECT_FALSE(f.closed());
  EXPECT_EQ(f.boundaryEdges, 0u);
  EXPECT_EQ(f.orientationFlips, 3u);

  // Three triangles on one edge (a fin on a closed box).
  Mesh fin = box;
  const std::uint32_t a = fin.indices[0], b = fin.indices[1];
  fin.positions.push_back(glm::vec3(5.0f, 5.0f, 5.0f));
  fin.normals.push_back(glm::vec3(0.0f, 0.0f, 1.0f));
  fin.indices.insert(fin.indices.end(), {a, b, static_cast<std::uint32_t>(fin.positions.size() - 1)});
  const SurfaceMeasures n = measureSurface(fin, glm::dmat4(1.0));
  EXPECT_FALSE(n.closed());
  EXPECT_EQ(n.nonManifoldEdges, 1u);
  EXPECT_EQ(n.boundaryEdges, 2u);

  // An open sheet: its rim.
  const SurfaceMeasures p = measureSurface(makePlane(2.0, 1.0), glm::dmat4(1.0));
  EXPECT_FALSE(p.closed());
  EXPECT_NEAR(p.area, 2.0, 1e-12);
  EXPECT_GE(p.boundaryEdges, 4u);
}

}  // namespace
}  // namespace mfr::test
