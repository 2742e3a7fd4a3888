#pragma once
// Constructive solid geometry over a scene's closed objects, evaluated per pixel on sorted
// fragment lists (image-space CSG): the tree, the postfix program the GPU runs (its words are
// defined in shaders/common/bindings.h, MFR_CSG_*), and the per-list classification shared by the
// oracle and the tests.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace mfr {

struct Fragment;
struct Scene;

struct CsgNode {
  enum class Op : std::uint32_t { Primitive = 0, Union = 1, Intersection = 2, Difference = 3 };
  Op op = Op::Primitive;
  std::uint32_t object = 0;       // Primitive: index into Scene::objects
  std::vector<CsgNode> children;  // Union/Intersection: ≥ 2; Difference: ≥ 2, the first minus all the others
};

struct CsgTree {
  std::optional<CsgNode> root;  // none: the scene has no CSG

  [[nodiscard]] bool empty() const { return !root.has_value(); }
  // Scene object indices of the primitives, each once, in first-use (left-to-right) order:
  // primitive i is bit i of an inside mask.
  [[nodiscard]] std::vector<std::uint32_t> primitives() const;
  // The tree as a postfix program (n-ary nodes as left-deep chains of binary ones): a primitive
  // word is MFR_CSG_PRIMITIVE | bit << 8, an operator word its opcode.
  [[nodiscard]] std::vector<std::uint32_t> program() const;
  // Whether a point inside exactly the primitives whose bits are set in insideMask lies in the solid.
  [[nodiscard]] bool inside(std::uint32_t insideMask) const;
};

// Image-space CSG classification of one pixel's sorted list (front to back), the rule the GPU
// operation "csg" implements (shaders/ops/csg.glsl): inside states start outside; a front-facing
// fragment of a primitive sets its bit, a back-facing one clears it; the visible fragment is the
// first at which the solid goes from outside to inside, or the first fragment of an object that
// is not in the tree (drawn as an ordinary opaque surface). Returns its index, or nothing.
// Bit i of `mirrored` reverses the facings of primitive i (csgMirroredPrimitives).
std::optional<std::size_t> csgVisibleFragment(const CsgTree& tree, std::span<const Fragment> sorted,
                                              std::uint32_t mirrored = 0);

// Bit i set: the transform of primitive i (CsgTree::primitives()) mirrors (negative determinant),
// which reverses its triangles' winding and so every facing the rasteriser and the oracle report
// for it; the classification flips those, so that a mirrored part (common in CAD assemblies)
// stays a solid instead of turning inside out.
std::uint32_t csgMirroredPrimitives(const Scene& scene);

// Throws mfr::Error naming the scene or object when the tree refers to a missing object, has more
// than MFR_CSG_MAX_PRIMITIVES primitives or more than MFR_CSG_MAX_PROGRAM program words, or a
// primitive's mesh is not closed (every edge, after merging vertices within 10⁻⁶ of the mesh's
// size — generated seams and poles differ in their last bits — shared by exactly two triangles).
void validateCsg(const Scene& scene);

}  // namespace mfr
