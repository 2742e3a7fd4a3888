// Section planes (scene/section.hpp): cut meshes checked against closed-form geometry — the volume
// and cap area of a cut box and sphere, closedness and outward orientation of what is left (also
// under mirrored, scaled and rotated transforms) — and the oracle's view of a capped box against
// the box that is already that shape. Plus the .mfrscene "section" key and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"
#include "mfr/scene/section.hpp"
#include "test_files.hpp"

namespace mfr {
namespace {

// Signed volume by the divergence theorem: positive for a closed, outward-wound surface.
double signedVolume(const Mesh& m, const glm::dmat4& transform = glm::dmat4(1.0)) {
  double v = 0.0;
  for (std::size_t t = 0; t < m.triangleCount(); ++t) {
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k)
      p[k] = glm::dvec3(transform * glm::dvec4(glm::dvec3(m.positions[m.indices[3 * t + k]]), 1.0));
    v += glm::dot(p[0], glm::cross(p[1], p[2])) / 6.0;
  }
  return v;
}

// Closed and consistently wound, geometrically: the triangles' vector areas Σ ½ (b − a) × (c − a)
// cancel (to 1e-6 of their total area). The topological test (every edge shared by exactly two
// triangles) is CSG's own validateCsg, used below.
bool closedAndConsistent(const Mesh& m) {
  glm::dvec3 sum(0.0);
  double total = 0.0;
  for (std::size_t t = 0; t < m.triangleCount(); ++t) {
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    const glm::dvec3 area = 0.5 * glm::cross(b - a, c - a);
    sum += area;
    total += glm::length(area);
  }
  return total > 0.0 && glm::length(sum) <= 1e-6 * total;
}

double capArea(const SectionedMesh& cut) {
  double area = 0.0;
  const Mesh& m = cut.mesh;
  for (std::size_t t = m.triangleCount() - cut.capTriangles; t < m.triangleCount(); ++t) {
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

TEST(Section, BoxCutInHalfIsAClosedHalfBoxWithAUnitCap) {
  const Mesh box = makeBox({1.0, 1.0, 1.0});
  ASSERT_NEAR(signedVolume(box), 1.0, 1e-6);
  // Keep z >= 0.2: dot((0,0,1), p) - 0.2 >= 0.
  const SectionedMesh cut = sectionMesh(box, {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(cut.outcome, SectionOutcome::kCapped);
  EXPECT_TRUE(cut.closed);
  EXPECT_GT(cut.capTriangles, 0u);
  EXPECT_NEAR(signedVolume(cut.mesh), 0.3, 1e-6);
  EXPECT_NEAR(capArea(cut), 1.0, 1e-6);
  EXPECT_TRUE(closedAndConsistent(cut.mesh));
  for (const glm::vec3& p : cut.mesh.positions) EXPECT_GE(p.z, 0.2f - 1e-6f);
  ASSERT_EQ(cut.mesh.normals.size(), cut.mesh.positions.size());
  const std::size_t capStart = cut.mesh.positions.size() - 3 * cut.capTriangles;
  for (std::size_t i = capStart; i < cut.mesh.positions.size(); ++i) {
    EXPECT_NEAR(cut.mesh.positions[i].z, 0.2f, 1e-6f);
    EXPECT_EQ(cut.mesh.normals[i], glm::vec3(0.0f, 0.0f, -1.0f));
  }
  // The other side: the complement, same cap area.
  const SectionedMesh other = sectionMesh(box, {0.0, 0.0, -1.0, 0.2}, true);
  ASSERT_EQ(other.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(signedVolume(other.mesh), 0.7, 1e-6);
  EXPECT_NEAR(capArea(other), 1.0, 1e-6);
  // Without caps: open, the same surface minus the cap.
  const SectionedMesh open = sectionMesh(box, {0.0, 0.0, 1.0, -0.2}, false);
  ASSERT_EQ(open.outcome, SectionOutcome::kCut);
  EXPECT_EQ(open.capTriangles, 0u);
  EXPECT_FALSE(closedAndConsistent(open.mesh));
}

TEST(Section, ObliqueCutOfASphereMatchesTheSphericalCap) {
  // Fine enough that the polyhedron is within 0.2 % of the sphere's volume.
  const double r = 1.5;
  const Mesh sphere = makeSphere(r, 192, 96);
  const double full = signedVolume(sphere);
  ASSERT_NEAR(full, 4.0 / 3.0 * std::numbers::pi * r * r * r, 2e-3 * full);
  const glm::dvec3 n = glm::normalize(glm::dvec3(1.0, -2.0, 0.5));
  const double d = 0.6;  // kept: dot(n, p) >= d, a cap of height r - d
  const SectionedMesh cut = sectionMesh(sphere, glm::dvec4(n, -d), true);
  ASSERT_EQ(cut.outcome, SectionOutcome::kCapped);
  EXPECT_TRUE(closedAndConsistent(cut.mesh));
  const double h = r - d;
  const double expectedVolume = std::numbers::pi * h * h * (3.0 * r - h) / 3.0;
  EXPECT_NEAR(signedVolume(cut.mesh) / (full / (4.0 / 3.0 * std::numbers::pi * r * r * r)), expectedVolume,
              2e-3 * expectedVolume);
  const double expectedDisc = std::numbers::pi * (r * r - d * d);
  EXPECT_NEAR(capArea(cut), expectedDisc, 5e-3 * expectedDisc);
  for (const glm::vec3& p : cut.mesh.positions) EXPECT_GE(glm::dot(n, glm::dvec3(p)), d - 1e-5);
}

TEST(Section, OpenSurfacesAreCutWithoutCapsAndWholeMeshesAreKeptOrRemoved) {
  const Mesh plane = makePlane(2.0, 2.0);  // z = 0, one-sided: not closed
  const SectionedMesh cut = sectionMesh(plane, {1.0, 0.0, 0.0, -0.5}, true);
  ASSERT_EQ(cut.outcome, SectionOutcome::kCut);
  EXPECT_FALSE(cut.closed);
  EXPECT_EQ(cut.capTriangles, 0u);
  double area = 0.0;
  for (std::size_t t = 0; t < cut.mesh.triangleCount(); ++t) {
    const glm::dvec3 a(cut.mesh.positions[cut.mesh.indices[3 * t]]), b(cut.mesh.positions[cut.mesh.indices[3 * t + 1]]),
        c(cut.mesh.positions[cut.mesh.indices[3 * t + 2]]);
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    EXPECT_GT(normal.z, 0.0);  // winding kept
    area += 0.5 * glm::length(normal);
  }
  EXPECT_NEAR(area, 0.5 * 2.0, 1e-6);  // x in [0.5, 1] of [-1, 1] × [-1, 1]
  EXPECT_EQ(sectionMesh(plane, {1.0, 0.0, 0.0, 5.0}, true).outcome, SectionOutcome::kKept);
  EXPECT_EQ(sectionMesh(plane, {1.0, 0.0, 0.0, -5.0}, true).outcome, SectionOutcome::kRemoved);
}

// Where the plane cuts it decides: a box without its +x face is open there — a cut through that
// face gets no cap — while a cut that misses the hole is capped as usual. A triangle doubled across
// the plane (scans and tessellations have them) counts once.
TEST(Section, OnlyTheCutLineMustBeClosed) {
  const Mesh box = makeBox({1.0, 1.0, 1.0});
  Mesh holed = box;
  holed.indices.clear();
  for (std::size_t t = 0; t < box.triangleCount(); ++t) {
    bool plusX = true;
    for (int k = 0; k < 3; ++k) plusX = plusX && box.positions[box.indices[3 * t + k]].x > 0.4f;
    if (!plusX)
      for (int k = 0; k < 3; ++k) holed.indices.push_back(box.indices[3 * t + k]);
  }
  ASSERT_EQ(holed.triangleCount(), box.triangleCount() - 2);
  const SectionedMesh throughHole = sectionMesh(holed, {0.0, 0.0, 1.0, -0.1}, true);  // z = 0.1 crosses +x
  EXPECT_FALSE(throughHole.closed);
  EXPECT_EQ(throughHole.outcome, SectionOutcome::kCut);
  EXPECT_EQ(throughHole.capTriangles, 0u);
  const SectionedMesh besideHole = sectionMesh(holed, {-1.0, 0.0, 0.0, 0.1}, true);  // keeps x <= 0.1
  EXPECT_TRUE(besideHole.closed);
  ASSERT_EQ(besideHole.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(besideHole), 1.0, 1e-6);

  Mesh doubled = box;
  for (std::size_t t = 0; t < box.triangleCount(); ++t) {
    float lo = 1.0f, hi = -1.0f;
    for (int k = 0; k < 3; ++k) {
      lo = std::min(lo, box.positions[box.indices[3 * t + k]].z);
      hi = std::max(hi, box.positions[box.indices[3 * t + k]].z);
    }
    if (lo < 0.0f && hi > 0.0f)  // a side triangle the plane z = 0 crosses
      for (int k = 0; k < 3; ++k) doubled.indices.push_back(box.indices[3 * t + k]);
  }
  ASSERT_GT(doubled.triangleCount(), box.triangleCount());
  const SectionedMesh cut = sectionMesh(doubled, {0.0, 0.0, 1.0, 0.0}, true);
  ASSERT_EQ(cut.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(cut), 1.0, 1e-6);
}

// Meshes of several shells, in one part: `b` joined to `a`, moved by `offset`, wound inside out if
// `inverted`, its vertices coloured `colour`.
Mesh joined(const Mesh& a, const Mesh& b, const glm::vec3& offset, bool inverted, const glm::vec4& colour) {
  Mesh m = a;
  if (m.colors.empty()) m.colors.assign(m.positions.size(), glm::vec4(1.0f));
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  for (std::size_t i = 0; i < b.positions.size(); ++i) {
    m.positions.push_back(b.positions[i] + offset);
    m.normals.push_back(inverted ? -b.normals[i] : b.normals[i]);
    m.colors.push_back(colour);
  }
  for (std::size_t t = 0; t < b.triangleCount(); ++t)
    for (const int k : {0, inverted ? 2 : 1, inverted ? 1 : 2}) m.indices.push_back(base + b.indices[3 * t + k]);
  return m;
}

// A self-intersecting part (a cartoon folding over at a tight bend, two tubes of one chain
// overlapping): its cut line crosses itself, and the cap fills what the loops wind around, once —
// the union of the overlapping sections — with a vertex at each crossing. A cavity wound inward
// stays open, as before.
TEST(Section, OverlappingShellsOfOnePartAreCappedByTheirUnion) {
  const Mesh unit = makeBox({1.0, 1.0, 1.0});
  const glm::vec4 red(1.0f, 0.0f, 0.0f, 1.0f);
  const Mesh overlapping = joined(unit, unit, {0.5f, 0.5f, 0.0f}, false, red);
  const SectionedMesh cut = sectionMesh(overlapping, {0.0, 0.0, 1.0, -0.2}, true);
  EXPECT_TRUE(cut.closed);
  ASSERT_EQ(cut.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(cut), 1.0 + 1.0 - 0.25, 1e-6);  // the union of the two unit squares
  const Mesh& m = cut.mesh;
  const std::size_t capStart = m.positions.size() - 3 * cut.capTriangles;
  std::size_t atCrossings = 0;
  for (std::size_t i = capStart; i < m.positions.size(); ++i) {
    EXPECT_NEAR(m.positions[i].z, 0.2f, 1e-6f);
    EXPECT_EQ(m.normals[i], glm::vec3(0.0f, 0.0f, -1.0f));
    // The squares' edges cross at (0.5, 0) and (0, 0.5); a crossing takes the colour beside it.
    const glm::vec2 p(m.positions[i]);
    if (glm::distance(p, glm::vec2(0.5f, 0.0f)) < 1e-6f || glm::distance(p, glm::vec2(0.0f, 0.5f)) < 1e-6f) {
      ++atCrossings;
      EXPECT_TRUE(m.colors[i] == red || m.colors[i] == glm::vec4(1.0f));
    }
  }
  EXPECT_GT(atCrossings, 0u);
  // Both inside out, the loops wind the other way round: the same union.
  const Mesh insideOut = joined(joined(Mesh{}, unit, {}, true, glm::vec4(1.0f)), unit, {0.5f, 0.5f, 0.0f}, true, red);
  const SectionedMesh mirrored = sectionMesh(insideOut, {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(mirrored.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(mirrored), 1.75, 1e-6);
  // Shells wound against each other wind 0 around their overlap, which stays open.
  const SectionedMesh opposed =
      sectionMesh(joined(unit, unit, {0.5f, 0.5f, 0.0f}, true, red), {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(opposed.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(opposed), 0.75 + 0.75, 1e-6);
  // Shells whose cut lines overlap along a line (boxes side by side, half overlapping): the
  // segments are collinear, and the crossings exact, so no constraint takes a detour.
  const SectionedMesh collinear =
      sectionMesh(joined(unit, unit, {0.5f, 0.0f, 0.0f}, false, red), {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(collinear.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(collinear), 1.5, 1e-6);
  // Shells whose cut lines share a stretch exactly, point for point: a 2 × 1 × 1 box holding the
  // unit box against its end face (the two x = −0.5 faces are one). The stretch counts for both
  // loops (as a doubled triangle's it would count once, and neither loop would close).
  const SectionedMesh shared =
      sectionMesh(joined(unit, makeBox({2.0, 1.0, 1.0}), {0.5f, 0.0f, 0.0f}, false, red), {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(shared.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(shared), 2.0, 1e-6);
  // Two copies of one box: every segment twice. Either reading closes the loops; the cap is one.
  const SectionedMesh copies = sectionMesh(joined(unit, unit, {}, false, red), {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(copies.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(copies), 1.0, 1e-6);
  // A cavity listed twice is one cavity: both readings close, and counting once leaves it open
  // (counting each use would wind −1 in it and fill it with an inward cap).
  const Mesh doubleCavity = joined(joined(makeBox({2.0, 2.0, 2.0}), unit, {}, true, red), unit, {}, true, red);
  const SectionedMesh cavity = sectionMesh(doubleCavity, {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(cavity.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(cavity), 4.0 - 1.0, 1e-6);
  // Both a doubled triangle and a stretch shared by two shells (about 10⁻⁶ long, where the plane
  // passes through a corner): counting repeats once leaves two open ends the weld joins, counting
  // each use two it cannot join. The reading is chosen after welding (a fuzzer's case).
  const std::vector<Object> boxes =
      loadModel(std::filesystem::path(MFR_TEST_DATA_DIR) / "sections" / "offset_boxes_doubled_triangle.off");
  ASSERT_EQ(boxes.size(), 1u);
  const SectionedMesh oblique = sectionMesh(
      *boxes[0].mesh,
      sectionPlaneEquation({{1.0, 0.5, 1.0}, {-0.39272011989098476, 1.151924692572371, -0.7241083188228018}, true}),
      true);
  EXPECT_EQ(oblique.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(oblique), 0.644486, 1e-5);
  // A surface wound inside out gets a cap that faces as it does: inward, and the cut box is again
  // closed and consistently wound (volume negative). Where shells overlap, each region's cap faces
  // as the shells winding around it.
  const SectionedMesh inverted = sectionMesh(joined(Mesh{}, unit, {}, true, red), {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(inverted.outcome, SectionOutcome::kCapped);
  EXPECT_TRUE(closedAndConsistent(inverted.mesh));
  EXPECT_NEAR(signedVolume(inverted.mesh), -0.3, 1e-6);
  for (std::size_t i = inverted.mesh.positions.size() - 3 * inverted.capTriangles; i < inverted.mesh.positions.size();
       ++i)
    EXPECT_EQ(inverted.mesh.normals[i], glm::vec3(0.0f, 0.0f, 1.0f));
  // A closed surface flattened into a plane: its cut points lie on one line and enclose nothing.
  Mesh flat;
  flat.positions = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, {1.0f, 0.0f, 1.0f}};
  flat.indices = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
  const SectionedMesh line = sectionMesh(flat, {0.0, 0.0, 1.0, -0.3}, true);
  EXPECT_EQ(line.outcome, SectionOutcome::kCut);
  EXPECT_EQ(line.capTriangles, 0u);
  // A cavity wound inward stays open.
  const Mesh hollow = joined(makeBox({2.0, 2.0, 2.0}), unit, {}, true, red);
  const SectionedMesh ring = sectionMesh(hollow, {0.0, 0.0, 1.0, -0.2}, true);
  ASSERT_EQ(ring.outcome, SectionOutcome::kCapped);
  EXPECT_NEAR(capArea(ring), 4.0 - 1.0, 1e-6);
}

// A box whose +x face is moved out by `gap` (its edges no longer meet the neighbouring faces'):
// a gap below 1e-3 of the size (the box's diagonal, 1.73) is joined and capped, a visible one is not.
TEST(Section, TinyGapsAlongTheCutAreJoined) {
  for (const double gap : {2e-6, 1.5e-3, 1e-2}) {
    SCOPED_TRACE(gap);
    Mesh box = makeBox({1.0, 1.0, 1.0});
    std::vector<bool> onPlusX(box.positions.size(), false);
    for (std::size_t t = 0; t < box.triangleCount(); ++t) {
      bool all = true;
      for (int k = 0; k < 3; ++k) all = all && box.normals[box.indices[3 * t + k]].x > 0.5f;
      for (int k = 0; k < 3 && all; ++k) onPlusX[box.indices[3 * t + k]] = true;
    }
    for (std::size_t i = 0; i < box.positions.size(); ++i)
      if (onPlusX[i]) box.positions[i].x += static_cast<float>(gap);
    const SectionedMesh cut = sectionMesh(box, {0.0, 0.0, 1.0, -0.1}, true);
    if (gap < 1.7e-3) {
      EXPECT_TRUE(cut.closed);
      ASSERT_EQ(cut.outcome, SectionOutcome::kCapped);
      EXPECT_NEAR(capArea(cut), 1.0, 1e-4 + gap);
    } else {
      EXPECT_FALSE(cut.closed);
      EXPECT_EQ(cut.outcome, SectionOutcome::kCut);
    }
  }
}

TEST(Section, VertexColoursAreInterpolatedOntoTheCutAndTheCap) {
  Mesh box = makeBox({2.0, 2.0, 2.0});
  box.colors.resize(box.positions.size());
  for (std::size_t i = 0; i < box.positions.size(); ++i)  // red at x = -1 to green at x = +1
    box.colors[i] = {0.5f - 0.5f * box.positions[i].x, 0.5f + 0.5f * box.positions[i].x, 0.0f, 1.0f};
  const SectionedMesh cut = sectionMesh(box, {0.0, 1.0, 0.0, 0.0}, true);  // keep y >= 0
  ASSERT_EQ(cut.outcome, SectionOutcome::kCapped);
  ASSERT_EQ(cut.mesh.colors.size(), cut.mesh.positions.size());
  for (std::size_t i = 0; i < cut.mesh.positions.size(); ++i) {
    const float x = cut.mesh.positions[i].x;
    EXPECT_NEAR(cut.mesh.colors[i].r, 0.5f - 0.5f * x, 1e-5f);
    EXPECT_NEAR(cut.mesh.colors[i].g, 0.5f + 0.5f * x, 1e-5f);
  }
}

Object object(const std::string& name, const Mesh& mesh, const glm::dmat4& transform) {
  Object o;
  o.name = name;
  o.mesh = std::make_shared<const Mesh>(mesh);
  o.transform = transform;
  return o;
}

TEST(Section, SceneObjectsAreCutInWorldSpaceWhateverTheirTransform) {
  Scene scene;
  scene.name = "parts";
  const glm::dmat4 rotated = glm::rotate(glm::translate(glm::dmat4(1.0), {0.3, -0.2, 0.1}), 0.7, {1.0, 1.0, 0.0});
  const glm::dmat4 mirrored = glm::scale(glm::translate(glm::dmat4(1.0), {0.0, 0.5, 0.0}), {-1.0, 2.0, 0.5});
  scene.objects.push_back(object("rotated", makeBox({1.0, 1.0, 1.0}), rotated));
  scene.objects.push_back(object("mirrored", makeSphere(0.8, 96, 48), mirrored));
  scene.objects.push_back(object("far", makeBox({1.0, 1.0, 1.0}), glm::translate(glm::dmat4(1.0), {0.0, 0.0, 10.0})));
  scene.objects.push_back(
      object("behind", makeBox({1.0, 1.0, 1.0}), glm::translate(glm::dmat4(1.0), {0.0, 0.0, -10.0})));
  SectionPlane plane;
  plane.point = {0.1, 0.2, 0.05};
  plane.normal = {0.0, 0.0, 3.0};  // not unit length: keep z >= 0.05
  scene.section = plane;
  SectionReport report;
  const Scene cut = sectionedScene(scene, &report);
  EXPECT_TRUE(cut.sectionCut);
  EXPECT_EQ(report.cut, 2u);
  EXPECT_EQ(report.capped, 2u);
  EXPECT_EQ(report.removed, 1u);
  EXPECT_TRUE(report.open.empty());
  EXPECT_TRUE(cut.objects[0].visible && cut.objects[1].visible && cut.objects[2].visible);
  EXPECT_FALSE(cut.objects[3].visible);
  EXPECT_EQ(cut.objects[2].mesh, scene.objects[2].mesh);  // untouched: shared, not copied
  for (int o = 0; o < 2; ++o) {
    SCOPED_TRACE(cut.objects[o].name);
    const Object& part = cut.objects[o];
    EXPECT_TRUE(closedAndConsistent(*part.mesh));
    for (const glm::vec3& p : part.mesh->positions)
      EXPECT_GE((part.transform * glm::dvec4(glm::dvec3(p), 1.0)).z, 0.05 - 1e-5);
    // Outward in world space: positive volume, times the transform's orientation.
    const double sign = glm::determinant(glm::dmat3(part.transform)) > 0.0 ? 1.0 : -1.0;
    EXPECT_GT(sign * signedVolume(*part.mesh, part.transform), 0.0);
    // Cap normals, through the normal matrix, face the cut-away side: world -z.
    const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(glm::dmat3(part.transform)));
    const glm::vec3 capNormal = part.mesh->normals.back();
    EXPECT_NEAR(glm::dot(glm::normalize(normalMatrix * glm::dvec3(capNormal)), glm::dvec3(0.0, 0.0, -1.0)), 1.0, 1e-6);
  }
  // The ellipsoid's cross-section at z = 0.05: an ellipse of semi-axes 0.8·r and 1.6·r, r² = 1 − zc²
  // (zc below), in world units — the transform's scale included.
  ASSERT_EQ(report.outcomes.size(), 4u);
  EXPECT_EQ(report.outcomes[2], SectionOutcome::kKept);
  EXPECT_EQ(report.outcomes[3], SectionOutcome::kRemoved);
  EXPECT_EQ(report.capAreas[2], 0.0);
  EXPECT_EQ(report.capAreas[3], 0.0);
  {
    const double zc = 0.05 / 0.4;
    const double ellipse = std::numbers::pi * 0.8 * 1.6 * (1.0 - zc * zc);
    EXPECT_NEAR(report.capAreas[1], ellipse, 5e-3 * ellipse);
  }
  // The sphere's world volume: an ellipsoid (semi-axes 0.8, 1.6, 0.4, centre z = 0) above z = 0.05.
  const double c = 0.4, zc = 0.05 / c;  // in the unit-sphere frame of the z axis
  const double expected = std::numbers::pi * 0.8 * 1.6 * c * (2.0 / 3.0 - zc + zc * zc * zc / 3.0);
  EXPECT_NEAR(-signedVolume(*cut.objects[1].mesh, cut.objects[1].transform), expected, 5e-3 * expected);
  // Applied once: a cut scene is not cut again.
  EXPECT_EQ(sectionedScene(cut).objects[0].mesh, cut.objects[0].mesh);
  // Nothing left.
  scene.section->point = {0.0, 0.0, 100.0};
  EXPECT_THROW((void)sectionedScene(scene), Error);
  scene.section->normal = {0.0, 0.0, 0.0};
  EXPECT_THROW(scene.validate(), Error);
}

// The report's cross-section areas are the caps' world areas: a cylinder of n sides (axis y, radius
// r, height 1) cut across its axis has the regular n-gon's area n/2 · r² · sin(2π/n), scaled by the
// transform's x and z scale, and keeps that area times the height left; a unit box cut by the
// oblique plane x = z + 0.1 keeps a prism of ½ · 0.9² × 1 over a 0.9·√2 × 1 rectangle.
TEST(Section, CrossSectionAreasAreTheCapsWorldAreas) {
  const int sides = 24;
  const double r = 0.5;
  const glm::dmat4 stretched = glm::scale(glm::translate(glm::dmat4(1.0), {4.0, 1.0, 0.0}), {2.0, 3.0, 1.5});
  Scene scene;
  scene.name = "cylinder and box";
  scene.objects.push_back(object("cylinder", makeCylinder(r, 1.0, sides), stretched));
  scene.objects.push_back(object("box", makeBox({1.0, 1.0, 1.0}), glm::dmat4(1.0)));
  scene.section = SectionPlane{{0.0, 1.39, 0.0}, {0.0, -1.0, 0.0}, true};  // keeps y ≤ 1.39
  SectionReport report;
  Scene cut = sectionedScene(scene, &report);
  ASSERT_EQ(report.outcomes.size(), 2u);
  EXPECT_EQ(report.outcomes[0], SectionOutcome::kCapped);
  EXPECT_EQ(report.outcomes[1], SectionOutcome::kKept);  // the box lies below the plane
  const double polygon = 0.5 * sides * r * r * std::sin(2.0 * std::numbers::pi / sides) * 2.0 * 1.5;
  EXPECT_NEAR(report.capAreas[0], polygon, 1e-6 * polygon);
  EXPECT_NEAR(report.totalCapArea(), polygon, 1e-6 * polygon);
  // World y of the cylinder: 1 + 3·[-0.5, 0.5] = [-0.5, 2.5]; kept up to 1.39.
  EXPECT_NEAR(signedVolume(*cut.objects[0].mesh, stretched), polygon * (1.39 + 0.5), 1e-5);

  scene.section = SectionPlane{{0.1, 0.0, 0.0}, {1.0, 0.0, -1.0}, true};  // keeps x ≥ z + 0.1
  cut = sectionedScene(scene, &report);
  EXPECT_EQ(report.outcomes[0], SectionOutcome::kKept);  // the cylinder lies at x ≥ 3, z ≤ 0.75
  EXPECT_EQ(report.outcomes[1], SectionOutcome::kCapped);
  EXPECT_NEAR(report.capAreas[1], 0.9 * std::sqrt(2.0), 1e-6);                    // 0.9·√2 × 1
  EXPECT_NEAR(signedVolume(*cut.objects[1].mesh, glm::dmat4(1.0)), 0.405, 1e-6);  // ½ · 0.9² × 1
}

// An L-shaped prism, y in [0, 1]: [0, 2] × [0, 1] in x × z below, [0, 1] × [1, 2] above, so its
// shoulder face (x in [1, 2], z = 1) lies in the plane z = 1. Outward wound, one vertex set per face.
Mesh makeLPrism() {
  const glm::dvec2 l[6] = {{0.0, 0.0}, {2.0, 0.0}, {2.0, 1.0}, {1.0, 1.0}, {1.0, 2.0}, {0.0, 2.0}};  // (x, z)
  Mesh m;
  const auto triangle = [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    for (const glm::dvec3& p : {a, b, c}) {
      m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
      m.positions.emplace_back(p);
    }
  };
  const auto at = [&](int i, double y) { return glm::dvec3(l[i % 6].x, y, l[i % 6].y); };
  for (const int i : {4, 5, 0, 1}) {  // the end faces, fanned from the reflex corner 3
    triangle(at(3, 0.0), at(i, 0.0), at(i + 1, 0.0));
    triangle(at(3, 1.0), at(i + 1, 1.0), at(i, 1.0));
  }
  for (int i = 0; i < 6; ++i) {
    triangle(at(i, 0.0), at(i, 1.0), at(i + 1, 1.0));
    triangle(at(i, 0.0), at(i + 1, 1.0), at(i + 1, 0.0));
  }
  if (signedVolume(m) < 0.0)
    for (std::size_t t = 0; t < m.triangleCount(); ++t) std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
  m.computeSmoothNormals();
  return m;
}

// A face lying in the plane: cut exactly at the shoulder, either way, what is left is a closed
// solid of the right volume with a cap of the right area (the cut is made a millionth of the
// size further in, where no vertex is, so the shoulder face is not left over inside the cap).
TEST(Section, AFaceLyingInThePlaneDoesNotOpenTheCut) {
  const Mesh prism = makeLPrism();
  ASSERT_NEAR(signedVolume(prism), 3.0, 1e-9);
  ASSERT_TRUE(closedAndConsistent(prism));
  const SectionedMesh upper = sectionMesh(prism, {0.0, 0.0, 1.0, -1.0}, true);  // keep z >= 1
  ASSERT_EQ(upper.outcome, SectionOutcome::kCapped);
  EXPECT_TRUE(closedAndConsistent(upper.mesh));
  EXPECT_NEAR(signedVolume(upper.mesh), 1.0, 1e-4);
  EXPECT_NEAR(capArea(upper), 1.0, 1e-4);
  const SectionedMesh lower = sectionMesh(prism, {0.0, 0.0, -1.0, 1.0}, true);  // keep z <= 1
  ASSERT_EQ(lower.outcome, SectionOutcome::kCapped);
  EXPECT_TRUE(closedAndConsistent(lower.mesh));
  EXPECT_NEAR(signedVolume(lower.mesh), 2.0, 1e-4);
  EXPECT_NEAR(capArea(lower), 2.0, 1e-4);
  // Touching the plane is not being cut: the whole prism is kept above z = 0 and removed below it.
  EXPECT_EQ(sectionMesh(prism, {0.0, 0.0, 1.0, 0.0}, true).outcome, SectionOutcome::kKept);
  EXPECT_EQ(sectionMesh(prism, {0.0, 0.0, -1.0, 0.0}, true).outcome, SectionOutcome::kRemoved);
}

// One solid split over two parts (a glTF mesh with a primitive per material): each part is open
// along the cut, together they are closed, so they get one cap — on the part with more of the cut
// line, in its own object space (moved, or mirrored), and with the mesh closed across the two parts.
TEST(Section, ASolidSplitOverTwoPartsIsCappedOnce) {
  const Mesh box = makeBox({1.0, 1.0, 1.0});
  // Triangles go to a part by their centroid's side of x = 0.1.
  Mesh first = box, second = box;
  first.indices.clear();
  second.indices.clear();
  for (std::size_t t = 0; t < box.triangleCount(); ++t) {
    float x = 0.0f;
    for (int k = 0; k < 3; ++k) x += box.positions[box.indices[3 * t + k]].x / 3.0f;
    Mesh& to = x < 0.1f ? first : second;
    for (int k = 0; k < 3; ++k) to.indices.push_back(box.indices[3 * t + k]);
  }
  ASSERT_GT(first.triangleCount(), 0u);
  ASSERT_GT(second.triangleCount(), 0u);
  // A part drawn through `transform`, its mesh moved back by the inverse, its
  // winding turned where the transform mirrors, so that the world shape is the box.
  const auto placed = [](const std::string& name, Mesh mesh, const glm::dmat4& transform) {
    const glm::dmat4 back = glm::inverse(transform);
    for (glm::vec3& p : mesh.positions) p = glm::vec3(back * glm::dvec4(glm::dvec3(p), 1.0));
    if (glm::determinant(glm::dmat3(transform)) < 0.0)
      for (std::size_t t = 0; t < mesh.triangleCount(); ++t)
        std::swap(mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]);
    return object(name, mesh, transform);
  };
  const glm::dmat4 moved = glm::rotate(glm::translate(glm::dmat4(1.0), {0.25, -0.5, 1.0}), 0.5 * std::numbers::pi,
                                       glm::dvec3(1.0, 0.0, 0.0));
  const glm::dmat4 mirror = glm::scale(glm::dmat4(1.0), {-1.0, 1.0, 1.0});
  // Both parts hold 4 segments of the cut line, so the cap goes to the first: moved, then mirrored.
  for (const bool firstMirrored : {false, true}) {
    SCOPED_TRACE(firstMirrored);
    Scene scene;
    scene.name = "split box";
    scene.objects.push_back(placed("first", first, firstMirrored ? mirror * moved : moved));
    scene.objects.push_back(placed("second", second, firstMirrored ? moved : mirror));
    scene.objects.push_back(object("elsewhere", makePlane(1.0, 1.0), glm::translate(glm::dmat4(1.0), {3.0, 0.0, 0.0})));
    scene.objects[2].mesh = std::make_shared<const Mesh>([] {
      Mesh sheet = makePlane(1.0, 1.0);  // turned upright so the plane z = 0.1 cuts it: open, alone
      for (glm::vec3& p : sheet.positions) p = {p.x, 0.0f, p.y};
      return sheet;
    }());
    scene.section = SectionPlane{{0.0, 0.0, 0.1}, {0.0, 0.0, 1.0}, true};
    SectionReport report;
    const Scene cut = sectionedScene(scene, &report);
    EXPECT_EQ(report.cut, 3u);
    EXPECT_EQ(report.capped, 2u);
    ASSERT_EQ(report.open.size(), 1u);
    EXPECT_EQ(report.open[0], "elsewhere");
    // Both parts in world space, as one mesh: closed, outward, the volume of the box above z = 0.1.
    Mesh joined;
    std::size_t capTriangles[2] = {0, 0};
    for (int o = 0; o < 2; ++o) {
      const Object& part = cut.objects[o];
      const bool mirrored = glm::determinant(glm::dmat3(part.transform)) < 0.0;
      for (std::size_t t = 0; t < part.mesh->triangleCount(); ++t) {
        glm::dvec3 p[3];
        for (int k = 0; k < 3; ++k)
          p[k] = glm::dvec3(part.transform *
                            glm::dvec4(glm::dvec3(part.mesh->positions[part.mesh->indices[3 * t + k]]), 1.0));
        if (mirrored) std::swap(p[1], p[2]);
        for (const glm::dvec3& q : p) {
          joined.indices.push_back(static_cast<std::uint32_t>(joined.positions.size()));
          joined.positions.emplace_back(q);
        }
        const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
        if (std::abs(p[0].z - 0.1) < 1e-6 && std::abs(p[1].z - 0.1) < 1e-6 && std::abs(p[2].z - 0.1) < 1e-6) {
          EXPECT_LT(n.z, 0.0);  // the cap faces the cut-away side, -z, in its winding and its normals
          const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(glm::dmat3(part.transform)));
          const glm::dvec3 normal(part.mesh->normals[part.mesh->indices[3 * t]]);
          EXPECT_NEAR(glm::normalize(normalMatrix * normal).z, -1.0, 1e-6);
          ++capTriangles[o];
        }
      }
    }
    EXPECT_TRUE(closedAndConsistent(joined));
    EXPECT_NEAR(signedVolume(joined), 0.4, 1e-6);
    EXPECT_GT(capTriangles[0] + capTriangles[1], 0u);
    EXPECT_TRUE(capTriangles[0] == 0 || capTriangles[1] == 0);  // one cap, on one part
    // The cross-section, the box's unit square, is reported once, on the part holding the cap.
    ASSERT_EQ(report.capAreas.size(), 3u);
    EXPECT_NEAR(report.capAreas[0] + report.capAreas[1], 1.0, 1e-6);
    EXPECT_EQ(report.capAreas[capTriangles[0] > 0 ? 1 : 0], 0.0);
    EXPECT_EQ(report.capAreas[2], 0.0);
    EXPECT_NEAR(report.totalCapArea(), 1.0, 1e-6);
    EXPECT_EQ(report.outcomes[0], SectionOutcome::kCapped);
    EXPECT_EQ(report.outcomes[1], SectionOutcome::kCapped);
    EXPECT_EQ(report.outcomes[2], SectionOutcome::kCut);
    // Caps off: no joint cap either.
    scene.section->caps = false;
    (void)sectionedScene(scene, &report);
    EXPECT_EQ(report.capped, 0u);
  }
}

// The CSG sample's drills are cylinders turned by 90°: vertices that should lie on y = 0 lie at
// ±1e-17. They count as on the plane, so every part is capped and stays a solid.
TEST(Section, VerticesWithinRoundingOfThePlaneAreOnIt) {
  Scene scene = makeCsgSampleScene();
  scene.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, true};
  SectionReport report;
  const Scene cut = sectionedScene(scene, &report);
  EXPECT_EQ(report.cut, scene.objects.size());
  EXPECT_EQ(report.capped, report.cut);
  EXPECT_TRUE(report.open.empty()) << report.open.front();
  for (const Object& o : cut.objects) EXPECT_TRUE(closedAndConsistent(*o.mesh)) << o.name;
  EXPECT_NO_THROW(validateCsg(cut));
}

// CSG's own closedness test is topological (every edge shared by exactly two triangles once
// coincident vertices merge): the caps keep every point of the cut line, so the cut solids pass it,
// on an oblique plane too.
TEST(Section, CutSolidsAreWatertightForCsg) {
  for (const glm::dvec3 normal : {glm::dvec3(0.3, -1.0, 0.6), glm::dvec3(1.0, 0.2, -0.1), glm::dvec3(0.0, 0.0, 1.0)}) {
    SCOPED_TRACE(normal.x);
    Scene scene = makeCsgSampleScene();
    scene.section = SectionPlane{{0.05, 0.1, -0.02}, normal, true};
    SectionReport report;
    const Scene cut = sectionedScene(scene, &report);
    EXPECT_EQ(report.capped, report.cut);
    EXPECT_NO_THROW(validateCsg(cut));
  }
}

// A plane between two shells of one part removes one whole and crosses no triangle: nothing was
// opened, so the part counts as capped (with no cap) and no note calls it open.
TEST(Section, RemovingWholeShellsOpensNothing) {
  const Mesh twoBoxes = joined(makeBox({1.0, 1.0, 1.0}), makeBox({1.0, 1.0, 1.0}), {3.0f, 0.0f, 0.0f}, false,
                               glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  const SectionedMesh cut = sectionMesh(twoBoxes, {1.0, 0.0, 0.0, -1.5}, true);
  EXPECT_EQ(cut.outcome, SectionOutcome::kCapped);
  EXPECT_TRUE(cut.closed);
  EXPECT_EQ(cut.capTriangles, 0u);
  EXPECT_EQ(cut.mesh.triangleCount(), 12u);
  EXPECT_TRUE(closedAndConsistent(cut.mesh));
  // Without caps asked for, it is reported as cut, as any part the plane changes.
  EXPECT_EQ(sectionMesh(twoBoxes, {1.0, 0.0, 0.0, -1.5}, false).outcome, SectionOutcome::kCut);
  // What is kept is open (a sheet kept, the box removed): reported as cut without a cap.
  const Mesh sheetAndBox =
      joined(makeBox({1.0, 1.0, 1.0}), makePlane(1.0, 1.0), {3.0f, 0.0f, 0.0f}, false, glm::vec4(1.0f));
  const SectionedMesh sheet = sectionMesh(sheetAndBox, {1.0, 0.0, 0.0, -1.5}, true);
  EXPECT_EQ(sheet.outcome, SectionOutcome::kCut);
  EXPECT_EQ(sheet.mesh.triangleCount(), 2u);
  EXPECT_EQ(describeCut(SectionOutcome::kCapped, 0.0), "; cut, closed without a cap of its own");
}

TEST(Section, OpenPartsAreReportedAndCapsCanBeTurnedOff) {
  Scene scene;
  scene.name = "mixed";
  scene.objects.push_back(object("sheet", makePlane(2.0, 2.0), glm::dmat4(1.0)));
  scene.objects.push_back(object("block", makeBox({1.0, 1.0, 1.0}), glm::dmat4(1.0)));
  scene.section = SectionPlane{{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, true};
  SectionReport report;
  (void)sectionedScene(scene, &report);
  EXPECT_EQ(report.cut, 2u);
  EXPECT_EQ(report.capped, 1u);
  ASSERT_EQ(report.open.size(), 1u);
  EXPECT_EQ(report.open[0], "sheet");
  scene.section->caps = false;
  const Scene uncapped = sectionedScene(scene, &report);
  EXPECT_EQ(report.capped, 0u);
  EXPECT_TRUE(report.open.empty());
  EXPECT_FALSE(closedAndConsistent(*uncapped.objects[1].mesh));
}

// The oracle's view of a unit box cut at z = 0 (keeping z <= 0) is the view of the box that has that
// shape from the start, [-0.5, 0.5]² × [-0.5, 0]: the cap is the top face, same depth, same normal,
// same colour.
TEST(Section, TheOracleSeesACappedBoxAsTheBoxOfThatShape) {
  Camera camera;
  camera.eye = {0.6, 0.9, 3.0};
  camera.target = {0.0, 0.0, -0.2};
  const int w = 64, h = 48;
  Scene cut;
  cut.name = "cut";
  cut.objects.push_back(object("box", makeBox({1.0, 1.0, 1.0}), glm::dmat4(1.0)));
  cut.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, true};
  Scene half;
  half.name = "half";
  half.objects.push_back(object("box", makeBox({1.0, 1.0, 0.5}), glm::translate(glm::dmat4(1.0), {0.0, 0.0, -0.25})));
  const FragmentLists a = castFragments(cut, camera, w, h);
  const FragmentLists b = castFragments(half, camera, w, h);
  std::size_t compared = 0, withFragments = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (a.isAmbiguous(x, y) || b.isAmbiguous(x, y)) continue;
      ++compared;
      const auto la = a.pixel(x, y), lb = b.pixel(x, y);
      ASSERT_EQ(la.size(), lb.size()) << x << "," << y;
      withFragments += la.empty() ? 0 : 1;
      for (std::size_t i = 0; i < la.size(); ++i) {
        EXPECT_NEAR(la[i].depth, lb[i].depth, 1e-6f) << x << "," << y;
        EXPECT_EQ(la[i].color, lb[i].color) << x << "," << y;
      }
    }
  EXPECT_GT(compared, static_cast<std::size_t>(w * h * 3 / 4));
  EXPECT_GT(withFragments, static_cast<std::size_t>(w * h / 8));
}

// A volume's slice is the plane's cross-section of its box: a grid-aligned plane gives the box's
// face (area and corners exactly), a plane x + y + z = 1.5 through a unit cube the regular hexagon
// of side √2/2 (area 3√3/4), each wound with the normal −n (a cap's); a plane beside the box or through one
// corner only gives nothing.
TEST(Section, AVolumeSliceIsThePlanesCrossSectionOfItsBox) {
  const auto polygonArea = [](const std::vector<glm::dvec3>& p) {
    glm::dvec3 sum(0.0);
    for (std::size_t i = 1; i + 1 < p.size(); ++i) sum += glm::cross(p[i] - p[0], p[i + 1] - p[0]);
    return 0.5 * sum;  // its vector area: |sum| the area, the direction the winding's normal
  };
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = {5, 3, 9};
  grid->values.assign(5 * 3 * 9, 1.0f);
  Volume box;
  box.grid = grid;
  box.origin = {1.0, -2.0, 0.0};
  box.spacing = {0.5, 2.0, 0.25};  // [1, 3] × [-2, 2] × [0, 2]
  const std::vector<glm::dvec3> face = volumeSlicePolygon(box, glm::dvec4(0.0, 0.0, -1.0, 0.5));  // keeps z <= 0.5
  ASSERT_EQ(face.size(), 4u);
  for (const glm::dvec3& p : face) {
    EXPECT_NEAR(p.z, 0.5, 1e-12);
    EXPECT_TRUE(std::abs(p.x - 1.0) < 1e-12 || std::abs(p.x - 3.0) < 1e-12) << p.x;
    EXPECT_TRUE(std::abs(p.y + 2.0) < 1e-12 || std::abs(p.y - 2.0) < 1e-12) << p.y;
  }
  EXPECT_NEAR(polygonArea(face).z, 8.0, 1e-9);  // 2 × 4, facing +z = −n

  // Rotated and moved: the same face, moved with it.
  Volume turned = box;
  turned.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, 10.0)) *
                     glm::rotate(glm::dmat4(1.0), glm::radians(90.0), glm::dvec3(0.0, 0.0, 1.0));
  const std::vector<glm::dvec3> moved = volumeSlicePolygon(turned, glm::dvec4(0.0, 0.0, 1.0, -10.5));
  ASSERT_EQ(moved.size(), 4u);
  EXPECT_NEAR(polygonArea(moved).z, -8.0, 1e-9);  // facing −z = −n

  auto unit = std::make_shared<VolumeGrid>();
  unit->dims = {2, 2, 2};
  unit->values.assign(8, 0.0f);
  Volume cube;
  cube.grid = unit;
  const glm::dvec3 n = glm::normalize(glm::dvec3(1.0));
  const std::vector<glm::dvec3> hexagon = volumeSlicePolygon(cube, glm::dvec4(n, -1.5 / std::sqrt(3.0)));
  ASSERT_EQ(hexagon.size(), 6u);
  const glm::dvec3 area = polygonArea(hexagon);
  EXPECT_NEAR(glm::length(area), 3.0 * std::sqrt(3.0) / 4.0, 1e-12);
  EXPECT_NEAR(glm::dot(glm::normalize(area), -n), 1.0, 1e-12);
  for (const glm::dvec3& p : hexagon) EXPECT_NEAR(p.x + p.y + p.z, 1.5, 1e-12);

  EXPECT_TRUE(volumeSlicePolygon(cube, glm::dvec4(0.0, 0.0, 1.0, -2.0)).empty());               // beside it
  EXPECT_TRUE(volumeSlicePolygon(cube, glm::dvec4(n, -3.0 / std::sqrt(3.0) + 1e-15)).empty());  // a corner
  // A plane on a face gives that face from either side (one side called it a miss: a hunt).
  for (int axis = 0; axis < 3; ++axis)
    for (const double at : {0.0, 1.0})
      for (const double sign : {1.0, -1.0}) {
        glm::dvec4 plane(0.0);
        plane[axis] = sign;
        plane.w = -sign * at;
        const std::vector<glm::dvec3> onFace = volumeSlicePolygon(cube, plane);
        ASSERT_EQ(onFace.size(), 4u) << axis << " " << at << " " << sign;
        EXPECT_NEAR(std::abs(polygonArea(onFace)[axis]), 1.0, 1e-12);
        for (const glm::dvec3& p : onFace) EXPECT_NEAR(p[axis], at, 1e-12);
      }
}

// Two volumes whose boxes overlap: their slices are not coplanar (they would z-fight) but one step
// apart, the first volume's in front, both inside the kept side. The oracle sees no depth tie over
// the overlap, and the first slice nearest.
TEST(Section, OverlappingVolumesSlicesAreOrderedNotTied) {
  const auto cube = [](const std::string& name, glm::dvec3 origin, float value) {
    auto grid = std::make_shared<VolumeGrid>();
    grid->dims = {3, 3, 3};
    grid->values.assign(27, value);
    Volume v;
    v.name = name;
    v.grid = grid;
    v.origin = origin;  // spacing 1: the box [origin, origin + 2]
    v.transfer = transferPreset("grayscale", 0.0, 1.0, 1.0);
    return v;
  };
  Scene scene;
  scene.name = "two volumes";
  scene.volumes = {cube("a", {0.0, 0.0, 0.0}, 0.2f), cube("b", {1.0, 1.0, 0.0}, 0.8f)};
  scene.section = SectionPlane{{0.0, 0.0, 1.0}, {0.0, 0.0, -1.0}, true, true};  // keeps z <= 1
  SectionReport report;
  const Scene cut = sectionedScene(scene, &report);
  ASSERT_EQ(report.slices, 2u);
  ASSERT_EQ(cut.objects.size(), 2u);
  EXPECT_EQ(cut.objects[0].name, "a slice");
  EXPECT_EQ(cut.objects[1].name, "b slice");
  const double step = 1e-4 * std::sqrt(12.0);  // 10⁻⁴ of the (largest) box's diagonal
  for (std::size_t i = 0; i < 2; ++i)
    for (const glm::vec3& p : cut.objects[i].mesh->positions)
      EXPECT_NEAR(p.z, 1.0 - step * static_cast<double>(i + 1), 1e-6) << cut.objects[i].name;

  Camera camera;
  camera.eye = {1.5, 1.5, 6.0};
  camera.target = {1.5, 1.5, 0.0};
  camera.up = {0.0, 1.0, 0.0};
  const int w = 48, h = 48;
  const FragmentLists lists = castFragments(cut, camera, w, h);
  std::size_t overlap = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto list = lists.pixel(x, y);
      if (list.size() != 2) continue;
      ++overlap;
      EXPECT_FALSE(lists.flags[lists.index(x, y)] & FragmentLists::kDepthTie) << x << "," << y;
      EXPECT_EQ(list[0].objectId, 0u) << x << "," << y;
      EXPECT_EQ(list[1].objectId, 1u) << x << "," << y;
    }
  EXPECT_GT(overlap, static_cast<std::size_t>(w * h / 20));
}

using SceneFileSection = test::TempDirTest;

TEST_F(SceneFileSection, SectionKeyAndItsErrors) {
  const std::string objects = R"("objects": [{"primitive": {"type": "box"}}])";
  const Scene scene = loadScene(write(
      "s.mfrscene", "{" + objects + R"(, "section": {"point": [0, 0.1, 0], "normal": [0, -1, 0], "caps": false}})"));
  ASSERT_TRUE(scene.section.has_value());
  EXPECT_EQ(scene.section->point, glm::dvec3(0, 0.1, 0));
  EXPECT_EQ(scene.section->normal, glm::dvec3(0, -1, 0));
  EXPECT_FALSE(scene.section->caps);
  EXPECT_FALSE(scene.section->slice);
  EXPECT_TRUE(
      loadScene(write("v.mfrscene",
                      "{" + objects + R"(, "section": {"point": [0, 0, 0], "normal": [1, 0, 0], "slice": true}})"))
          .section->slice);
  EXPECT_TRUE(
      loadScene(write("d.mfrscene", "{" + objects + R"(, "section": {"point": [0, 0, 0], "normal": [1, 0, 0]}})"))
          .section->caps);
  EXPECT_FALSE(loadScene(write("n.mfrscene", "{" + objects + "}")).section.has_value());
  const std::pair<std::string, std::string> bad[] = {
      {R"("section": [1, 2])", "section: expected an object"},
      {R"("section": {"point": [0, 0, 0]})", "section: expected \"point\" and \"normal\""},
      {R"("section": {"point": [0, 0], "normal": [1, 0, 0]})", "section.point: expected an array of 3 numbers"},
      {R"("section": {"point": [0, 0, 0], "normal": [0, 0, 0]})", "section.normal: must not be zero"},
      // Below Scene::validate's bound: the message named neither the file nor the key (a bug hunt).
      {R"("section": {"point": [0, 0, 0], "normal": [0, 0, 1e-30]})",
       "section.normal: must not be zero (a length above 1e-12)"},
      // Its length overflows: normalised it was NaN, refused later as "section plane: …" without the file.
      {R"("section": {"point": [0, 0, 0], "normal": [0, 0, 1e308]})", "section.normal: too long to normalise"},
      {R"("section": {"point": [0, 0, 0], "normal": [0, 0, 1], "caps": 1})", "section.caps: expected true or false"},
      {R"("section": {"point": [0, 0, 0], "normal": [0, 0, 1], "slice": "yes"})",
       "section.slice: expected true or false"},
  };
  for (const auto& [json, mention] : bad) {
    SCOPED_TRACE(json);
    const std::filesystem::path path = write("bad.mfrscene", "{" + objects + ", " + json + "}");
    test::expectFileError(path, mention, [&] { return loadScene(path).name; });
  }
}

}  // namespace
}  // namespace mfr
