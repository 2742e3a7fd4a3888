// The cartoon's geometry (mfr::cartoonMesh) on traces laid out by hand, against what the shape
// must be: a loop is a round tube of the loop radius around the curve, which passes through every
// trace point; a helix's band is 2 × 1.35 Å wide along the residues' C→O and 2 × 0.25 Å thick; a
// strand ends in an arrowhead 1.5 × its width; every segment is one closed, outward-wound tube;
// colours step halfway between residues and fields are interpolated. Also DSSP
// (mfr::assignSecondaryStructure) on an ideal α-helix built from its textbook internal geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/scene/cartoon.hpp"
#include "poly_alanine.hpp"
#include "mfr/scene/measure.hpp"

namespace mfr::test {
namespace {

std::vector<CartoonResidue> straightRun(std::size_t n, SecondaryStructure s, const glm::dvec3& guide) {
  std::vector<CartoonResidue> run;
  for (std::size_t i = 0; i < n; ++i) {
    CartoonResidue r;
    r.trace = glm::dvec3(3.8 * static_cast<double>(i), 0.0, 0.0);
    r.guide = guide;
    r.structure = s;
    r.color = glm::vec4(static_cast<float>(i) / 10.0f, 0.5f, 0.5f, 1.0f);
    r.values = {static_cast<float>(10 * i)};
    run.push_back(r);
  }
  return run;
}

CartoonOptions withField() {
  CartoonOptions o;
  o.fieldNames = {"residue"};
  return o;
}

TEST(Cartoon, LoopIsARoundTubeThroughEveryTracePointClosedAndOutward) {
  const std::vector<CartoonResidue> run = straightRun(5, SecondaryStructure::Loop, glm::dvec3(0, 1, 0));
  const CartoonOptions o = withField();
  const Mesh mesh = cartoonMesh({run}, o);
  // 4 residue intervals × 8 rings → 33 rings of 16; the caps a fan of 16 each.
  EXPECT_EQ(mesh.triangleCount(), 32u * 16u * 2u + 2u * 16u);
  for (const glm::vec3& p : mesh.positions) {
    EXPECT_GE(p.x, -1e-5);
    EXPECT_LE(p.x, 15.2 + 1e-5);
  }
  // The tube's wall: every ring vertex 0.2 Å from the axis (the curve is the straight line).
  for (std::size_t v = 0; v < 33u * 16u; ++v)
    EXPECT_NEAR(std::hypot(mesh.positions[v].y, mesh.positions[v].z), 0.2, 1e-5) << v;
  const SurfaceMeasures m = measureSurface(mesh, glm::dmat4(1.0));
  EXPECT_TRUE(m.closed());
  // A 16-gon of circumradius 0.2 swept 15.2 Å: its area × length, positive (outward).
  const double polygon = 0.5 * 16.0 * 0.2 * 0.2 * std::sin(2.0 * std::numbers::pi / 16.0);
  EXPECT_NEAR(m.volume, polygon * 15.2, 1e-6);
  // Through every trace point, curving one: a bent run passes through its corners.
  std::vector<CartoonResidue> bent = run;
  bent[2].trace.y = 2.0;
  bent[3].trace = glm::dvec3(9.0, 5.0, 1.0);
  const Mesh curved = cartoonMesh({bent}, o);
  for (std::size_t i = 0; i < bent.size(); ++i) {
    glm::dvec3 centre(0.0);
    for (std::size_t v = 0; v < 16; ++v) centre += glm::dvec3(curved.positions[i * 8 * 16 + v]);
    centre /= 16.0;
    EXPECT_LT(glm::distance(centre, bent[i].trace), 1e-5) << "residue " << i;
  }
  EXPECT_TRUE(measureSurface(curved, glm::dmat4(1.0)).closed());
  EXPECT_GT(measureSurface(curved, glm::dmat4(1.0)).volume, 0.0);
}

TEST(Cartoon, HelixIsABandAlongTheGuide) {
  // A band along x whose width lies along the guide (0, 0, 1): extents 1.35 in z, 0.25 in y.
  const Mesh mesh = cartoonMesh({straightRun(4, SecondaryStructure::Helix, glm::dvec3(0.3, 0.0, 2.0))}, withField());
  double zMax = 0.0, yMax = 0.0;
  for (std::size_t v = 0; v < 25u * 16u; ++v) {
    zMax = std::max(zMax, std::abs(double(mesh.positions[v].z)));
    yMax = std::max(yMax, std::abs(double(mesh.positions[v].y)));
  }
  EXPECT_NEAR(zMax, 1.35, 1e-5);
  EXPECT_NEAR(yMax, 0.25, 1e-5);
  // A guide that flips from residue to residue (a strand's carbonyls) gives the very same band.
  std::vector<CartoonResidue> flipping = straightRun(4, SecondaryStructure::Helix, glm::dvec3(0, 0, 1));
  flipping[1].guide = glm::dvec3(0, 0, -1);
  flipping[3].guide = glm::dvec3(0, 0, -1);
  const Mesh same = cartoonMesh({flipping}, withField());
  ASSERT_EQ(same.positions.size(), mesh.positions.size());
  for (std::size_t v = 0; v < 25u * 16u; ++v) {
    EXPECT_NEAR(same.positions[v].y, mesh.positions[v].y, 1e-5) << v;
    EXPECT_NEAR(same.positions[v].z, mesh.positions[v].z, 1e-5) << v;
  }
  EXPECT_TRUE(measureSurface(same, glm::dmat4(1.0)).closed());
}

TEST(Cartoon, StrandEndsInAnArrowhead) {
  std::vector<CartoonResidue> run = straightRun(6, SecondaryStructure::Strand, glm::dvec3(0, 0, 1));
  run[5].structure = SecondaryStructure::Loop;  // the strand's last residue is 4
  const Mesh mesh = cartoonMesh({run}, withField());
  // Half-width (z) per ring: 1.4 along the strand, 2.1 at the arrow's base (u = 3.5), falling
  // linearly to the loop's 0.2 at u = 4.5; then the loop.
  for (std::size_t k = 0; k <= 40; ++k) {
    const double u = static_cast<double>(k) / 8.0;
    double z = 0.0;
    for (std::size_t v = 0; v < 16; ++v) z = std::max(z, std::abs(double(mesh.positions[k * 16 + v].z)));
    double expected = 1.4;
    if (u >= 3.5 && u < 4.5) expected = 2.1 + (0.2 - 2.1) * (u - 3.5);
    if (u >= 4.5) expected = 0.2;
    EXPECT_NEAR(z, expected, 1e-5) << "u = " << u;
  }
  EXPECT_TRUE(measureSurface(mesh, glm::dmat4(1.0)).closed());
}

TEST(Cartoon, ColoursStepHalfwayAndFieldsInterpolate) {
  const Mesh mesh = cartoonMesh({straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0))}, withField());
  ASSERT_EQ(mesh.fields.size(), 1u);
  EXPECT_EQ(mesh.fields[0].name, "residue");
  ASSERT_EQ(mesh.fields[0].values.size(), mesh.positions.size());
  for (std::size_t k = 0; k <= 16; ++k) {
    const double u = static_cast<double>(k) / 8.0;
    EXPECT_NEAR(mesh.fields[0].values[k * 16], 10.0 * u, 1e-4) << u;
    const auto nearest = static_cast<float>(std::lround(u));
    EXPECT_FLOAT_EQ(mesh.colors[k * 16].r, nearest / 10.0f) << u;
  }
}

TEST(Cartoon, SegmentsAreSeparateTubesAndShortOnesDrawNothing) {
  const CartoonOptions o = withField();
  std::vector<CartoonResidue> second = straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0));
  for (CartoonResidue& r : second) r.trace.y += 20.0;
  const Mesh two = cartoonMesh({straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0)), second,
                                straightRun(1, SecondaryStructure::Helix, glm::dvec3(0, 1, 0))},
                               o);
  EXPECT_EQ(two.triangleCount(), 2u * (16u * 16u * 2u + 2u * 16u));
  EXPECT_TRUE(measureSurface(two, glm::dmat4(1.0)).closed());
  EXPECT_EQ(cartoonMesh({}, o).triangleCount(), 0u);
  // No guide anywhere (a nucleic acid's P trace): a tube all the same.
  std::vector<CartoonResidue> unguided = straightRun(4, SecondaryStructure::Loop, glm::dvec3(0, 1, 0));
  for (CartoonResidue& r : unguided) r.guide.reset();
  EXPECT_TRUE(measureSurface(cartoonMesh({unguided}, o), glm::dmat4(1.0)).closed());
}

// A nucleic acid's backbone (P trace, no guide): PyMOL's 0.5 Å tube, and from the curve at each
// nucleotide a closed 0.25 Å rod to its base atom, in the nucleotide's colour and values.
TEST(Cartoon, NucleicAcidsAreHalfAngstromTubesWithLaddersToTheirBases) {
  const CartoonOptions o = withField();
  std::vector<CartoonResidue> run = straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0));
  for (CartoonResidue& r : run) {
    r.guide.reset();
    r.nucleic = true;
    r.ladder = r.trace + glm::dvec3(0.0, 6.0, 0.0);  // straight out sideways, 6 Å
  }
  run[2].ladder.reset();  // a nucleotide without its base atoms: no rod
  const Mesh mesh = cartoonMesh({run}, o);
  EXPECT_TRUE(measureSurface(mesh, glm::dmat4(1.0)).closed());
  // The tube: 17 rings of 16 and two caps; each rod: 8 sides, capped (makeTube's 4·8 triangles).
  EXPECT_EQ(mesh.triangleCount(), (16u * 16u * 2u + 2u * 16u) + 2u * (4u * 8u));
  std::size_t onTube = 0, atBase = 0;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::dvec3 p(mesh.positions[v]);
    if (p.y < 1.0) {  // the backbone: 0.5 Å about the x axis (the rods start inside it)
      const double r = std::hypot(p.y, p.z);
      if (p.x > 0.0 && p.x < 7.6) {
        EXPECT_LE(r, 0.5 + 1e-5);
        onTube += std::abs(r - 0.5) < 1e-5 ? 1 : 0;
      }
      continue;
    }
    // A rod: 0.25 Å about its axis, reaching y = 6 at its base; residue 0's or 1's colour and value.
    const std::size_t i = p.x < 1.9 ? 0 : 1;
    EXPECT_LE(std::hypot(p.x - run[i].trace.x, p.z), 0.25 + 1e-5);
    EXPECT_LE(p.y, 6.0 + 1e-5);
    atBase += std::abs(p.y - 6.0) < 1e-5 ? 1 : 0;
    EXPECT_EQ(mesh.colors[v], run[i].color);
    EXPECT_EQ(mesh.fields[0].values[v], run[i].values[0]);
  }
  EXPECT_GT(onTube, 100u);
  EXPECT_GT(atBase, 2u * 8u);
}

TEST(Cartoon, BadInputIsRefused) {
  std::vector<CartoonResidue> run = straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0));
  run[1].trace.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)cartoonMesh({run}, withField()), Error);
  EXPECT_THROW((void)cartoonMesh({straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0))}, CartoonOptions{}),
               Error);  // values for a field not named
  CartoonOptions zero = withField();
  zero.sides = 2;
  EXPECT_THROW((void)cartoonMesh({straightRun(3, SecondaryStructure::Loop, glm::dvec3(0, 1, 0))}, zero), Error);
}

// ---- DSSP on an ideal α-helix -------------------------------------------------------------------

TEST(SecondaryStructureRule, IdealAlphaHelixAndExtendedChain) {
  // φ = −57°, ψ = −47°: every C=O(i) bonds N–H(i + 4); DSSP makes residues 2 … n − 1 helix (the
  // first and the last have no consecutive turns on their side).
  const std::vector<BackboneResidue> helix = polyAlanine(12, -57.0, -47.0);
  const std::vector<SecondaryStructure> ss = assignSecondaryStructure(helix);
  ASSERT_EQ(ss.size(), 12u);
  EXPECT_EQ(ss.front(), SecondaryStructure::Loop);
  EXPECT_EQ(ss.back(), SecondaryStructure::Loop);
  for (std::size_t i = 1; i + 1 < ss.size(); ++i) EXPECT_EQ(ss[i], SecondaryStructure::Helix) << i;
  // Fully extended (φ = ψ = 180°): one strand alone has no partner, so no strand and no helix.
  for (const SecondaryStructure s : assignSecondaryStructure(polyAlanine(12, 180.0, 180.0)))
    EXPECT_EQ(s, SecondaryStructure::Loop);
  // A residue without its O takes part in nothing; a chain too short for a turn is all loop.
  std::vector<BackboneResidue> broken = helix;
  broken[6].o.reset();
  const std::vector<SecondaryStructure> withGap = assignSecondaryStructure(broken);
  EXPECT_EQ(withGap[6], SecondaryStructure::Loop);
  EXPECT_EQ(assignSecondaryStructure({}).size(), 0u);
  EXPECT_EQ(assignSecondaryStructure(polyAlanine(3, -57.0, -47.0)),
            std::vector<SecondaryStructure>(3, SecondaryStructure::Loop));
}

}  // namespace
}  // namespace mfr::test
