// Image-space CSG on the CPU: the tree's postfix program and truth tables (worked out by hand),
// the per-list classification on hand-built lists, the checks on trees and meshes, the scene
// file's "csg" key, and — the independent reference — CGAL's exact Booleans (corefinement) cast by
// the oracle against the classification of the original scene's lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/csg.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/scene_file.hpp"
#include "csg_reference.hpp"
#include "test_files.hpp"

namespace mfr {
namespace {

using Op = CsgNode::Op;
using namespace test::csg;  // NOLINT: the CGAL reference and its scene helpers

CsgNode prim(std::uint32_t object) {
  CsgNode n;
  n.op = Op::Primitive;
  n.object = object;
  return n;
}

CsgNode node(Op op, std::vector<CsgNode> children) {
  CsgNode n;
  n.op = op;
  n.children = std::move(children);
  return n;
}

CsgTree tree(CsgNode root) {
  CsgTree t;
  t.root = std::move(root);
  return t;
}

// A primitive word as bindings.h defines it: opcode in the low byte, the primitive's bit above.
constexpr std::uint32_t word(std::uint32_t bit) {
  return MFR_CSG_PRIMITIVE | bit << 8;
}

glm::dmat4 translate(double x, double y, double z) {
  return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z));
}
glm::dmat4 rotate(double degrees, const glm::dvec3& axis) {
  return glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::normalize(axis));
}

// The message of the mfr::Error that f throws ("" and a failure when it throws none).
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no mfr::Error thrown";
  return "";
}

// ---------------------------------------------------------------------------------------------
// The tree

TEST(CsgTree, ProgramIsPostfixWithLeftDeepChains) {
  // difference(#3, union(#1, #4, #0), #1): primitives in first-use order are objects 3, 1, 4, 0,
  // so bits 0, 1, 2, 3 (object 1's second use keeps bit 1). Postfix, each n-ary node a left-deep
  // chain: 3 [1 4 ∪ 0 ∪] − 1 −.
  const CsgTree t = tree(node(Op::Difference, {prim(3), node(Op::Union, {prim(1), prim(4), prim(0)}), prim(1)}));
  EXPECT_EQ(t.primitives(), (std::vector<std::uint32_t>{3, 1, 4, 0}));
  const std::vector<std::uint32_t> expected = {
      word(0), word(1),           word(2), MFR_CSG_UNION, word(3), MFR_CSG_UNION, MFR_CSG_DIFFERENCE,
      word(1), MFR_CSG_DIFFERENCE};
  EXPECT_EQ(t.program(), expected);
  // Written out: words 0x000, 0x100, 0x200, 1, 0x300, 1, 3, 0x100, 3.
  EXPECT_EQ(t.program(), (std::vector<std::uint32_t>{0x000, 0x100, 0x200, 1, 0x300, 1, 3, 0x100, 3}));
  // It is inside exactly when bit 0 is set and bits 1..3 are clear: a ∧ ¬(b ∨ c ∨ d) ∧ ¬b.
  for (std::uint32_t mask = 0; mask < 16; ++mask) EXPECT_EQ(t.inside(mask), mask == 1) << mask;
  EXPECT_TRUE(t.inside(1u | 16u | 0x80000000u));  // bits of no primitive do not matter

  // A single primitive: one word; an intersection of two: a b ∩.
  EXPECT_EQ(tree(prim(7)).program(), (std::vector<std::uint32_t>{0x000}));
  EXPECT_EQ(tree(node(Op::Intersection, {prim(2), prim(5)})).program(),
            (std::vector<std::uint32_t>{0x000, 0x100, MFR_CSG_INTERSECTION}));
  // The empty tree: no primitives, no program, never inside.
  const CsgTree empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_TRUE(empty.primitives().empty());
  EXPECT_TRUE(empty.program().empty());
  EXPECT_FALSE(empty.inside(0xffffffffu));
}

TEST(CsgTree, TruthTables) {
  // Objects 0 (bit 0, "a") and 1 (bit 1, "b"); masks 0, a, b, ab.
  const bool unionTable[4] = {false, true, true, true};
  const bool intersectionTable[4] = {false, false, false, true};
  const bool differenceTable[4] = {false, true, false, false};
  const CsgTree u = tree(node(Op::Union, {prim(0), prim(1)}));
  const CsgTree i = tree(node(Op::Intersection, {prim(0), prim(1)}));
  const CsgTree d = tree(node(Op::Difference, {prim(0), prim(1)}));
  for (std::uint32_t mask = 0; mask < 4; ++mask) {
    SCOPED_TRACE(mask);
    EXPECT_EQ(u.inside(mask), unionTable[mask]);
    EXPECT_EQ(i.inside(mask), intersectionTable[mask]);
    EXPECT_EQ(d.inside(mask), differenceTable[mask]);
  }
  // Operand order matters for difference: b − a is inside at mask b only.
  const CsgTree ba = tree(node(Op::Difference, {prim(1), prim(0)}));
  EXPECT_EQ(ba.primitives(), (std::vector<std::uint32_t>{1, 0}));  // object 1 is bit 0 now
  EXPECT_FALSE(ba.inside(0));
  EXPECT_TRUE(ba.inside(1));  // inside object 1 only
  EXPECT_FALSE(ba.inside(2));
  EXPECT_FALSE(ba.inside(3));

  // union(intersection(a, b), difference(c, a)) with a, b, c = objects 0, 1, 2 (bits 0, 1, 2):
  // (a ∧ b) ∨ (c ∧ ¬a). Masks 0..7 = ∅, a, b, ab, c, ac, bc, abc:
  //   ∅ F; a F; b F; ab T; c T; ac F (c but a); bc T; abc T (ab).
  const CsgTree nested =
      tree(node(Op::Union, {node(Op::Intersection, {prim(0), prim(1)}), node(Op::Difference, {prim(2), prim(0)})}));
  const bool nestedTable[8] = {false, false, false, true, true, false, true, true};
  for (std::uint32_t mask = 0; mask < 8; ++mask) EXPECT_EQ(nested.inside(mask), nestedTable[mask]) << mask;

  // Three-operand difference a − b − c: inside a alone only; three-operand intersection: all three.
  const CsgTree d3 = tree(node(Op::Difference, {prim(0), prim(1), prim(2)}));
  const CsgTree i3 = tree(node(Op::Intersection, {prim(0), prim(1), prim(2)}));
  for (std::uint32_t mask = 0; mask < 8; ++mask) {
    EXPECT_EQ(d3.inside(mask), mask == 1) << mask;
    EXPECT_EQ(i3.inside(mask), mask == 7) << mask;
  }
}

// ---------------------------------------------------------------------------------------------
// The classification on hand-built lists. Sphere A is object 0, sphere B object 1, X (object 7) is
// not in the tree; depths only order the list.

Fragment frag(float depth, std::uint32_t objectId, bool frontFacing, std::uint32_t color = 0xFF000000u) {
  return {depth, color, objectId, frontFacing};
}

std::optional<std::size_t> visible(const CsgTree& t, const std::vector<Fragment>& list) {
  return csgVisibleFragment(t, std::span<const Fragment>(list));
}

TEST(CsgVisibleFragment, SphereAMinusSphereB) {
  const CsgTree aMinusB = tree(node(Op::Difference, {prim(0), prim(1)}));
  // Entering A first: at A's front face the mask becomes {a}, inside → the first fragment.
  EXPECT_EQ(visible(aMinusB, {frag(0.2f, 0, true), frag(0.3f, 1, true), frag(0.5f, 0, false), frag(0.6f, 1, false)}),
            std::optional<std::size_t>(0));
  // B in front: B's front face {b} outside, A's front face {a, b} still outside (in the hole),
  // B's back face {a} inside: the visible surface is B's back face, the wall of the hole.
  EXPECT_EQ(visible(aMinusB, {frag(0.2f, 1, true), frag(0.3f, 0, true), frag(0.5f, 1, false), frag(0.6f, 0, false)}),
            std::optional<std::size_t>(2));
  // B covers A along the whole ray: {b}, {a, b}, {b}, ∅ — never inside.
  EXPECT_EQ(visible(aMinusB, {frag(0.2f, 1, true), frag(0.3f, 0, true), frag(0.5f, 0, false), frag(0.6f, 1, false)}),
            std::nullopt);
  // Only B: never inside.
  EXPECT_EQ(visible(aMinusB, {frag(0.2f, 1, true), frag(0.6f, 1, false)}), std::nullopt);
  // X in front is an ordinary opaque surface: it is returned at once.
  EXPECT_EQ(visible(aMinusB, {frag(0.1f, 7, true), frag(0.2f, 0, true), frag(0.5f, 0, false)}),
            std::optional<std::size_t>(0));
  // X behind the hole's wall is hidden; X inside the hole (before the wall) is seen; back-facing
  // X counts the same.
  EXPECT_EQ(visible(aMinusB, {frag(0.2f, 1, true), frag(0.3f, 0, true), frag(0.5f, 1, false), frag(0.55f, 7, true)}),
            std::optional<std::size_t>(2));
  EXPECT_EQ(visible(aMinusB, {frag(0.2f, 1, true), frag(0.3f, 0, true), frag(0.4f, 7, false), frag(0.5f, 1, false)}),
            std::optional<std::size_t>(2));
  // Empty list: nothing.
  EXPECT_EQ(visible(aMinusB, {}), std::nullopt);

  // Union: the first front face of either; intersection: the front face that completes {a, b}.
  const CsgTree aOrB = tree(node(Op::Union, {prim(0), prim(1)}));
  const CsgTree aAndB = tree(node(Op::Intersection, {prim(0), prim(1)}));
  const std::vector<Fragment> overlap = {frag(0.2f, 0, true), frag(0.3f, 1, true), frag(0.5f, 0, false),
                                         frag(0.6f, 1, false)};
  EXPECT_EQ(visible(aOrB, overlap), std::optional<std::size_t>(0));
  EXPECT_EQ(visible(aAndB, overlap), std::optional<std::size_t>(1));
  // Disjoint along the ray: the intersection is empty, the union shows A.
  const std::vector<Fragment> apart = {frag(0.2f, 0, true), frag(0.3f, 0, false), frag(0.5f, 1, true),
                                       frag(0.6f, 1, false)};
  EXPECT_EQ(visible(aAndB, apart), std::nullopt);
  EXPECT_EQ(visible(aOrB, apart), std::optional<std::size_t>(0));
  // The rule starts every ray outside: a list that starts with a back face (the camera inside A,
  // not supported) clears a bit that was never set and shows nothing of A − B.
  EXPECT_EQ(visible(aMinusB, {frag(0.5f, 0, false)}), std::nullopt);
}

TEST(CsgComposite, OpaqueVisibleColourOrBackground) {
  // Two pixels: (0) B's front, A's front, B's back, A's back → B's back face (0.2, 0.4, 1.0) with
  // α 0.6, drawn opaque; (1) only B → background (0.1, 0.5, 0.9) → (26, 128, 230) (25.5 → 26, 127.5
  // → 128, 229.5 → 230: round half away from zero, like compositeOver).
  FragmentLists lists;
  lists.width = 2;
  lists.height = 1;
  lists.fragments = {frag(0.2f, 1, true, 0x11223344u),  frag(0.3f, 0, true, 0x55667788u),
                     frag(0.5f, 1, false, 0x99FF6633u), frag(0.6f, 0, false, 0x01020304u),
                     frag(0.2f, 1, true, 0x11223344u),  frag(0.6f, 1, false, 0x11223344u)};
  lists.offsets = {0, 4, 6};
  lists.flags = {0, 0};
  Scene scene;  // no objects: compositeCsg reads the tree and the background (and transforms)
  scene.csg = tree(node(Op::Difference, {prim(0), prim(1)}));
  scene.background = glm::vec3(0.1f, 0.5f, 0.9f);
  const ImageRGBA8 image = compositeCsg(lists, scene);
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 1);
  EXPECT_EQ(image.at(0, 0)[0], 0x33);
  EXPECT_EQ(image.at(0, 0)[1], 0x66);
  EXPECT_EQ(image.at(0, 0)[2], 0xFF);
  EXPECT_EQ(image.at(0, 0)[3], 255);
  EXPECT_EQ(image.at(1, 0)[0], 26);
  EXPECT_EQ(image.at(1, 0)[1], 128);
  EXPECT_EQ(image.at(1, 0)[2], 230);
  EXPECT_EQ(image.at(1, 0)[3], 255);
  // No tree: an error, not an image.
  scene.csg = CsgTree{};
  EXPECT_THROW(compositeCsg(lists, scene), Error);
}

// ---------------------------------------------------------------------------------------------
// Checks on trees and meshes

// Scene "checks": a box, a plane (open), a sphere, a cylinder, a torus, a tube.
Scene checkScene() {
  Scene s;
  s.name = "checks";
  addObject(s, "box", makeBox(glm::dvec3(1.0, 2.0, 3.0)));
  addObject(s, "sheet", makePlane(1.0, 1.0));
  addObject(s, "ball", makeSphere(1.5));
  addObject(s, "drill", makeCylinder(0.3, 4.0));
  addObject(s, "ring", makeTorus(1.0, 0.2));
  addObject(s, "pipe", makeTube({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 1}}, 0.1));
  return s;
}

TEST(CsgValidate, ClosedPrimitivesPass) {
  // The generated sphere, cylinder, torus and tube compute seam and pole vertices twice (sin 2π ≠
  // 0): they are closed only once nearly coincident vertices are merged.
  Scene s = checkScene();
  s.csg = tree(node(Op::Union, {prim(0), prim(2), prim(3), prim(4), prim(5)}));
  EXPECT_NO_THROW(validateCsg(s));
  EXPECT_NO_THROW(s.validate());
  s.csg = tree(node(Op::Difference, {prim(2), prim(3)}));
  EXPECT_NO_THROW(validateCsg(s));
  // Coarse and fine tessellations too (the merge distance follows the mesh's size).
  Scene scaled;
  scaled.name = "scaled";
  addObject(scaled, "tiny", makeSphere(1e-4, 7, 3));
  addObject(scaled, "huge", makeSphere(1e5, 300, 150));
  addObject(scaled, "coarse", makeTorus(2.0, 0.5, 3, 3));
  scaled.csg = tree(node(Op::Union, {prim(0), prim(1), prim(2)}));
  EXPECT_NO_THROW(validateCsg(scaled));
  // The empty tree checks nothing, even with an open mesh in the scene.
  Scene none = checkScene();
  EXPECT_NO_THROW(validateCsg(none));
}

TEST(CsgValidate, ZeroAreaTrianglesAreIgnored) {
  // A box plus a sliver (0, 0, 0) on its bottom edge: corners (−½, −1, −3/2) and (½, −1, −3/2) of
  // the 1×2×3 box and their midpoint, collinear: zero area, no edges counted.
  Mesh box = makeBox(glm::dvec3(1.0, 2.0, 3.0));
  const auto mid = static_cast<std::uint32_t>(box.positions.size());
  box.positions.emplace_back(0.0f, -1.0f, -1.5f);
  box.normals.emplace_back(0.0f, -1.0f, 0.0f);
  std::uint32_t a = 0, b = 0;
  for (std::uint32_t i = 0; i < mid; ++i) {
    if (box.positions[i] == glm::vec3(-0.5f, -1.0f, -1.5f)) a = i;
    if (box.positions[i] == glm::vec3(0.5f, -1.0f, -1.5f)) b = i;
  }
  box.indices.insert(box.indices.end(), {a, mid, b});
  Scene s;
  s.name = "sliver";
  addObject(s, "box", std::move(box));
  addObject(s, "other", makeBox(glm::dvec3(1.0)));
  s.csg = tree(node(Op::Union, {prim(0), prim(1)}));
  EXPECT_NO_THROW(validateCsg(s));
}

TEST(CsgValidate, Errors) {
  const auto check = [](const Scene& s, const std::string& part1, const std::string& part2) {
    const std::string what = errorOf([&] { validateCsg(s); });
    EXPECT_NE(what.find(part1), std::string::npos) << what;
    EXPECT_NE(what.find(part2), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    // Scene::validate runs the same checks.
    EXPECT_THROW(s.validate(), Error);
  };
  Scene s = checkScene();
  // An open mesh: the plane's 2 triangles have 5 edges, the 4 sides used once, the diagonal twice.
  s.csg = tree(node(Op::Difference, {prim(0), prim(1)}));
  check(s, "object 'sheet'", "not a closed surface: 4 edges on the border or shared by more than two triangles");
  // An object index out of range (6 objects).
  s.csg = tree(node(Op::Union, {prim(0), prim(6)}));
  check(s, "scene 'checks'", "object 6");
  // Operators with fewer than two operands, a primitive with operands.
  s.csg = tree(node(Op::Union, {prim(0)}));
  check(s, "scene 'checks'", "union with 1 operand");
  s.csg = tree(node(Op::Difference, {}));
  check(s, "scene 'checks'", "difference with 0 operand");
  CsgNode withChildren = prim(0);
  withChildren.children = {prim(2), prim(3)};
  s.csg = tree(withChildren);
  check(s, "scene 'checks'", "has operands");
  // No mesh.
  Scene noMesh = checkScene();
  noMesh.objects[2].mesh.reset();
  noMesh.csg = tree(node(Op::Union, {prim(0), prim(2)}));
  const std::string what = errorOf([&] { validateCsg(noMesh); });
  EXPECT_NE(what.find("object 'ball': has no mesh"), std::string::npos) << what;
  // Two copies of a box in one mesh: its 18 edges (12 sides, 6 face diagonals) each used 4 times.
  Mesh twice = makeBox(glm::dvec3(1.0));
  const auto n = static_cast<std::uint32_t>(twice.positions.size());
  const std::size_t indexCount = twice.indices.size();
  twice.positions.insert(twice.positions.end(), twice.positions.begin(), twice.positions.end());
  twice.normals.insert(twice.normals.end(), twice.normals.begin(), twice.normals.end());
  for (std::size_t i = 0; i < indexCount; ++i) twice.indices.push_back(twice.indices[i] + n);
  Scene doubled;
  doubled.name = "doubled";
  addObject(doubled, "double box", std::move(twice));
  addObject(doubled, "box", makeBox(glm::dvec3(0.5)));
  doubled.csg = tree(node(Op::Difference, {prim(1), prim(0)}));
  check(doubled, "object 'double box'", "not a closed surface: 18 edges");
}

TEST(CsgValidate, Limits) {
  // 33 boxes: one too many primitives; 32 pass; 32 distinct plus a repeat needs 33 + 32 = 65 words.
  Scene s;
  s.name = "many";
  for (int i = 0; i < 33; ++i) addObject(s, "box " + std::to_string(i), makeBox(glm::dvec3(1.0)), translate(i, 0, 0));
  std::vector<CsgNode> leaves;
  for (std::uint32_t i = 0; i < 32; ++i) leaves.push_back(prim(i));
  s.csg = tree(node(Op::Union, leaves));
  EXPECT_EQ(s.csg.program().size(), 63u);
  EXPECT_NO_THROW(validateCsg(s));
  std::vector<CsgNode> repeated = leaves;
  repeated.push_back(prim(5));
  s.csg = tree(node(Op::Union, repeated));
  EXPECT_EQ(s.csg.primitives().size(), 32u);
  std::string what = errorOf([&] { validateCsg(s); });
  EXPECT_NE(what.find("65 program words (at most 64)"), std::string::npos) << what;
  leaves.push_back(prim(32));
  s.csg = tree(node(Op::Union, leaves));
  what = errorOf([&] { validateCsg(s); });
  EXPECT_NE(what.find("scene 'many': CSG tree has 33 distinct objects (at most 32)"), std::string::npos) << what;
  // The bit stack: a right-deep chain a ∪ (b ∪ (c ∪ …)) of 32 leaves needs 32 entries, within the
  // limit (a left-deep chain needs 2).
  CsgNode right = prim(31);
  for (int i = 30; i >= 0; --i) right = node(Op::Union, {prim(static_cast<std::uint32_t>(i)), right});
  s.csg = tree(right);
  EXPECT_EQ(s.csg.program().size(), 63u);
  EXPECT_NO_THROW(validateCsg(s));
  // The result is inside when any bit is set, whichever tree shape.
  EXPECT_FALSE(s.csg.inside(0));
  EXPECT_TRUE(s.csg.inside(1u << 31));
  EXPECT_TRUE(s.csg.inside(1u << 7));
}

// ---------------------------------------------------------------------------------------------
// The scene file's "csg" key

std::string csgFile(const std::string& csg) {
  return R"({"objects": [
    {"name": "block", "primitive": {"type": "box", "size": [2, 1, 1]}},
    {"name": "drill x", "primitive": {"type": "cylinder", "radius": 0.2, "height": 3},
     "transform": {"rotate": [0, 0, 90]}},
    {"name": "drill y", "primitive": {"type": "cylinder", "radius": 0.2, "height": 3}},
    {"name": "ball", "primitive": {"type": "sphere", "radius": 0.6}},
    {"name": "sheet", "primitive": {"type": "plane"}},
    {"name": "twin", "primitive": {"type": "box"}},
    {"name": "twin", "primitive": {"type": "box"}}
  ], "csg": )" +
         csg + "}";
}

TEST(CsgSceneFile, NestedTreeParses) {
  const Scene s = parseSceneFile(
      csgFile(R"({"difference": ["block", {"union": ["drill x", "drill y"]}, {"intersection": ["ball", "block"]}]})"),
      ".", "csg.mfrscene");
  ASSERT_FALSE(s.csg.empty());
  const CsgNode& root = *s.csg.root;
  EXPECT_EQ(root.op, Op::Difference);
  ASSERT_EQ(root.children.size(), 3u);
  EXPECT_EQ(root.children[0].op, Op::Primitive);
  EXPECT_EQ(root.children[0].object, 0u);
  EXPECT_EQ(root.children[1].op, Op::Union);
  ASSERT_EQ(root.children[1].children.size(), 2u);
  EXPECT_EQ(root.children[1].children[0].object, 1u);
  EXPECT_EQ(root.children[1].children[1].object, 2u);
  EXPECT_EQ(root.children[2].op, Op::Intersection);
  ASSERT_EQ(root.children[2].children.size(), 2u);
  EXPECT_EQ(root.children[2].children[0].object, 3u);
  EXPECT_EQ(root.children[2].children[1].object, 0u);
  // Objects 0, 1, 2, 3 are bits 0..3: 0 [1 2 ∪] − [3 0 ∩] −.
  EXPECT_EQ(s.csg.program(), (std::vector<std::uint32_t>{0x000, 0x100, 0x200, MFR_CSG_UNION, MFR_CSG_DIFFERENCE, 0x300,
                                                         0x000, MFR_CSG_INTERSECTION, MFR_CSG_DIFFERENCE}));
  // A bare name is a tree too; no key, no tree.
  EXPECT_EQ(parseSceneFile(csgFile(R"("ball")"), ".", "csg.mfrscene").csg.root->object, 3u);
  EXPECT_TRUE(parseSceneFile(R"({"objects": [{"primitive": {"type": "box"}}]})", ".", "plain.mfrscene").csg.empty());
}

TEST(CsgSceneFile, BadTreesNameTheFileAndPath) {
  const auto expectError = [](const std::string& csg, const std::string& reason) {
    SCOPED_TRACE(csg);
    const std::string what = errorOf([&] { parseSceneFile(csgFile(csg), ".", "csg.mfrscene"); });
    EXPECT_EQ(what.rfind("csg.mfrscene: ", 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
  };
  expectError(R"({"difference": ["block", {"union": ["nope", "drill y"]}]})",
              "csg.mfrscene: csg.difference[1].union[0]: no object named 'nope'");
  expectError(R"({"union": ["twin", "block"]})", "csg.union[0]: 2 objects are named 'twin'");
  expectError(R"({"union": ["block"]})", "csg.union: expected an array of at least 2 operands");
  expectError(R"({"union": "block"})", "csg.union: expected an array of at least 2 operands");
  expectError(R"({"union": ["block", "ball"], "difference": ["block", "ball"]})", "csg: expected an object's name");
  expectError(R"({"xor": ["block", "ball"]})", "csg.xor: unknown CSG operator");
  expectError(R"({})", "csg: expected an object's name");
  expectError(R"(3)", "csg: expected an object's name");
  expectError(R"(["block", "ball"])", "csg: expected an object's name");
  expectError(R"({"union": ["block", 4]})", "csg.union[1]: expected an object's name");
  expectError(R"({"union": ["block", {"difference": ["ball", null]}]})", "csg.union[1].difference[1]: expected");
  expectError(R"({"difference": ["block", "sheet"]})",
              "csg.mfrscene: csg: object 'sheet': not a closed surface: 4 edges on the border");
}

class CsgSceneFileOnDisk : public test::TempDirTest {};

TEST_F(CsgSceneFileOnDisk, LoadSceneNamesTheFile) {
  const auto good = write("good.mfrscene", csgFile(R"({"difference": ["block", "drill x"]})"));
  const Scene s = loadScene(good);
  EXPECT_EQ(s.csg.primitives(), (std::vector<std::uint32_t>{0, 1}));
  // Too many primitives, and an open mesh: one line starting with the path.
  std::string objects, names;
  for (int i = 0; i < 33; ++i) {
    objects += std::string(i ? "," : "") + R"({"name": "b)" + std::to_string(i) + R"(", "primitive": {"type": "box"}})";
    names += std::string(i ? "," : "") + "\"b" + std::to_string(i) + "\"";
  }
  // Nesting deeper than any program of 64 words can hold is refused while parsing: 100,000 levels
  // crashed the parser's recursion (found by a bug hunt); 32 levels still reach the word limit.
  const auto nested = [](int levels) {
    std::string open, close;
    for (int i = 0; i < levels; ++i) {
      open += R"({"union": [)";
      close += R"(, "ball"]})";
    }
    return open + "\"block\"" + close;
  };
  const auto deep = write("deep.mfrscene", csgFile(nested(100000)));
  std::string deepError = errorOf([&] { loadScene(deep); });
  EXPECT_EQ(deepError, deep.string() + ": csg: nested more than 32 levels deep (a CSG program holds at most 64 words)");
  deepError = errorOf([&] { loadScene(write("deep32.mfrscene", csgFile(nested(32)))); });
  EXPECT_NE(deepError.find("CSG tree needs 65 program words (at most 64)"), std::string::npos) << deepError;
  const auto many = write("many.mfrscene", R"({"objects": [)" + objects + R"(], "csg": {"union": [)" + names + "]}}");
  const auto open = write("open.mfrscene", csgFile(R"({"union": ["sheet", "block"]})"));
  for (const auto& [path, reason] : {std::pair{many, std::string("CSG tree has 33 distinct objects (at most 32)")},
                                     std::pair{open, std::string("object 'sheet': not a closed surface")}}) {
    const std::string what = errorOf([&] { loadScene(path); });
    EXPECT_EQ(what.rfind(path.string() + ": csg: ", 0), 0u) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// ---------------------------------------------------------------------------------------------
// The independent reference: CGAL's exact Booleans (tests/support/csg_reference.hpp).

// A rotated box and a sphere overlapping one of its corners; camera outside both in both views.
Scene boxAndSphere() {
  Scene s;
  s.name = "box and sphere";
  addObject(s, "box", makeBox(glm::dvec3(2.4, 1.8, 2.0)), rotate(25.0, {1.0, 2.0, 0.5}), {0.9f, 0.3f, 0.2f, 1.0f});
  addObject(s, "ball", makeSphere(1.25, 40, 20), translate(0.9, 0.5, 0.6), {0.2f, 0.5f, 0.9f, 1.0f});
  return s;
}

TEST(CsgAgainstCgal, BoxAndSphere) {
  Scene scene = boxAndSphere();
  const SurfaceMesh box = toCgal(scene.objects[0]);
  const SurfaceMesh ball = toCgal(scene.objects[1]);
  const struct {
    Op op;
    Boolean boolean;
    std::uint32_t first, second;
    const char* name;
    int minHits;
  } cases[] = {{Op::Difference, Boolean::Difference, 0, 1, "box - ball", 1500},
               {Op::Difference, Boolean::Difference, 1, 0, "ball - box", 1150},
               {Op::Union, Boolean::Union, 0, 1, "box + ball", 2400},
               {Op::Intersection, Boolean::Intersection, 0, 1, "box * ball", 650}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    scene.name = c.name;
    scene.csg = tree(node(c.op, {prim(c.first), prim(c.second)}));
    const SurfaceMesh& a = c.first == 0 ? box : ball;
    const SurfaceMesh& b = c.first == 0 ? ball : box;
    compareBothViews(scene, referenceScene(c.name, boolean(c.boolean, a, b)), c.minHits);
  }
}

TEST(CsgAgainstCgal, TwoSpheres) {
  Scene scene;
  scene.name = "sphere - sphere";
  addObject(scene, "a", makeSphere(1.3, 36, 18), translate(-0.4, 0.0, 0.0));
  addObject(scene, "b", makeSphere(1.0, 30, 15), translate(0.6, 0.3, 0.5) * rotate(40.0, {1.0, 0.0, 1.0}));
  scene.csg = tree(node(Op::Difference, {prim(0), prim(1)}));
  compareBothViews(
      scene,
      referenceScene(scene.name, boolean(Boolean::Difference, toCgal(scene.objects[0]), toCgal(scene.objects[1]))),
      1350);
}

TEST(CsgAgainstCgal, NestedTreeAndAnOrdinarySurface) {
  // (box ∩ ball) − drill, and a rod through the drilled hole that is in no tree: the reference
  // scene holds CGAL's result and the rod, whose first fragment is the nearer of the two.
  Scene scene;
  scene.name = "(box * ball) - drill, rod";
  addObject(scene, "box", makeBox(glm::dvec3(2.4, 2.2, 2.0)), rotate(15.0, {0.3, 1.0, 0.2}));
  addObject(scene, "ball", makeSphere(1.45, 40, 20), translate(0.1, -0.05, 0.08));
  addObject(scene, "drill", makeCylinder(0.5, 4.0, 32), rotate(80.0, {1.0, 0.1, 0.0}));
  addObject(scene, "rod", makeBox(glm::dvec3(0.2, 0.2, 4.2)), rotate(-8.0, {0.0, 1.0, 0.0}));
  scene.csg = tree(node(Op::Difference, {node(Op::Intersection, {prim(0), prim(1)}), prim(2)}));
  const SurfaceMesh solid =
      boolean(Boolean::Difference, boolean(Boolean::Intersection, toCgal(scene.objects[0]), toCgal(scene.objects[1])),
              toCgal(scene.objects[2]));
  Scene reference = referenceScene(scene.name, solid);
  reference.objects.push_back(scene.objects[3]);
  compareBothViews(scene, reference, 1450);
}

// The viewer's text form of a tree (parseCsgText / csgText): names in, names out, blank is no
// tree, and what the scene file refuses is refused here too, with the JSON path.
TEST(CsgText, RoundTripAndErrors) {
  Scene scene;
  scene.name = "text";
  addObject(scene, "block", makeBox(glm::dvec3(2.0, 1.0, 1.0)), glm::dmat4(1.0));
  addObject(scene, "drill \"x\"", makeCylinder(0.2, 3.0, 16), glm::dmat4(1.0));
  addObject(scene, "sheet", makePlane(1.0, 1.0), glm::dmat4(1.0));
  const std::string text = R"({"difference":["block",{"union":["drill \"x\"","block"]}]})";
  const CsgTree t = parseCsgText(text, scene);
  EXPECT_EQ(t.primitives(), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(csgText(t, scene), text);
  EXPECT_TRUE(parseCsgText(" \n\t", scene).empty());
  EXPECT_EQ(csgText(CsgTree{}, scene), "");
  const auto refused = [&](const std::string& bad, const std::string& mention) {
    try {
      (void)parseCsgText(bad, scene);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  };
  refused(R"({"union": ["block"]})", "csg.union");
  refused(R"({"union": ["block", "nope"]})", "no object named 'nope'");
  refused(R"({"union": ["block", )", "not JSON");
  refused(R"({"difference": ["block", "sheet"]})", "not a closed surface");
}

// A mirrored part (negative determinant, as CAD assemblies instance left and right parts): its
// winding and so every reported facing are reversed; the classification flips them back. The
// drill is symmetric under x → −x about its axis, so the mirrored drill fills the same volume as
// the plain one, whose CGAL difference is the reference.
TEST(CsgAgainstCgal, MirroredPartStaysASolid) {
  Scene scene;
  scene.name = "block - mirrored drill";
  addObject(scene, "block", makeBox(glm::dvec3(3.0, 2.0, 2.2)), rotate(10.0, {0.0, 1.0, 0.0}));
  const glm::dmat4 drill = rotate(90.0, {0.0, 0.0, 1.0}) * translate(0.0, 0.0, 0.3);
  addObject(scene, "drill", makeCylinder(0.55, 4.0, 32), drill * glm::scale(glm::dmat4(1.0), {-1.0, 1.0, 1.0}));
  scene.csg = tree(node(Op::Difference, {prim(0), prim(1)}));
  EXPECT_EQ(csgMirroredPrimitives(scene), 2u);
  Object plain = scene.objects[1];
  plain.transform = drill;
  const SurfaceMesh solid = boolean(Boolean::Difference, toCgal(scene.objects[0]), toCgal(plain));
  compareBothViews(scene, referenceScene(scene.name, solid), 1500);
}

TEST(CsgAgainstCgal, ThreeOperandDifference) {
  // block − drill x − drill y, a left-deep chain, against two CGAL differences.
  Scene scene;
  scene.name = "block - drill x - drill y";
  addObject(scene, "block", makeBox(glm::dvec3(3.0, 2.0, 2.2)), rotate(10.0, {0.0, 1.0, 0.0}));
  addObject(scene, "drill x", makeCylinder(0.55, 4.0, 32), rotate(90.0, {0.0, 0.0, 1.0}) * translate(0.0, 0.0, 0.3));
  addObject(scene, "drill y", makeCylinder(0.45, 3.0, 32), translate(0.7, 0.0, -0.2));
  scene.csg = tree(node(Op::Difference, {prim(0), prim(1), prim(2)}));
  const SurfaceMesh solid =
      boolean(Boolean::Difference, boolean(Boolean::Difference, toCgal(scene.objects[0]), toCgal(scene.objects[1])),
              toCgal(scene.objects[2]));
  compareBothViews(scene, referenceScene(scene.name, solid), 2100);
}

}  // namespace
}  // namespace mfr
