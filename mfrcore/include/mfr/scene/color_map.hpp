#pragma once
// Surfaces coloured by a field of their mesh (ParaView's "Color by"): the named colour maps, the
// value → colour arithmetic both renderers share, and colorByField, which puts a field of the
// mesh (Mesh::fields) into Mesh::scalars and sets the material's FieldColors.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/mesh.hpp"
#include "mfr/scene/scene.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr {

struct ColorMap {
  std::string name;
  std::vector<glm::vec3> table;  // MFR_COLOR_MAP_SIZE entries evenly over [0, 1]
  glm::vec3 nanColor{1.0f, 1.0f, 0.0f};
};

// "cool-warm" (Moreland's diverging map, ParaView's default), "viridis", "magma", "rainbow"
// (blue → red through the hues) and "grayscale", in this order (the GPU's table rows).
const std::vector<std::string>& colorMapNames();
// Throws mfr::Error("colour map NAME", "unknown … (available: …)").
const ColorMap& colorMap(const std::string& name);
int colorMapIndex(const std::string& name);  // its row; throws like colorMap

// The colour of `value` under `map` over [range.x, range.y]: clamped to the ends, the map's NaN
// colour for NaN, the middle of the map for an empty range. The arithmetic of
// shaders/common/color_map.glsl, in the same float precision.
glm::vec3 mapFieldValue(const ColorMap& map, float value, const glm::vec2& range);

// A vertex's value as both renderers interpolate it: clamped to the range widened by
// MFR_COLOR_MAP_BAND spans on either side (infinities would interpolate into NaN); NaN stays NaN.
// The same float arithmetic as shaders/common/scene.vert.
float boundFieldValue(float value, const glm::vec2& range);

// The component `which` names of an array `base` with `components` components — "N" (0 ≤ N <
// components) or "magnitude" (-1) — as in "velocity:2" / "velocity:magnitude" for surface fields and
// volume files alike; anything else throws FieldNotFound(what, …) listing the valid spellings.
int fieldComponent(const std::string& base, const std::string& which, int components, const std::string& what);

// The fields a mesh can be coloured by: each of Mesh::fields by name and, for one of several
// components (a vector), also "name:N" for N ≥ 1 and "name:magnitude" ("name" is component 0).
std::vector<std::string> fieldNames(const Mesh& mesh);

// One value per tuple of `field` (a name of fieldNames) and whether it is cell data. Throws
// FieldNotFound(what, …) listing the fields there are.
struct FieldValues {
  std::vector<float> values;
  bool cellData = false;
};
FieldValues fieldValues(const Mesh& mesh, const std::string& field, const std::string& what);

// The smallest and largest finite value, if there is one (what mfr info reports).
std::optional<glm::dvec2> finiteSpan(const std::vector<float>& values);
// The same as a colour map's range: an empty span — or one within float rounding of a constant,
// at most 2^-20 of its magnitude — widened to its middle ± 1; [0, 1] without any.
glm::dvec2 fieldRange(const std::vector<float>& values);

// Colours `object` by `field` of its mesh with `map` over `range` (default: fieldRange of the
// field). The object gets a mesh of its own (others sharing its mesh keep theirs) whose scalars
// hold the field: per vertex for point data; for cell data every triangle gets corners of its own,
// all with its value (the mesh's point fields are carried along). Throws FieldNotFound for a field
// the mesh does not have, mfr::Error for an unknown map or a range that is not finite with
// low < high — naming `object.name`.
void colorByField(Object& object, const std::string& field, const std::string& map = "cool-warm",
                  const std::optional<glm::dvec2>& range = std::nullopt);

// The scene's volumes sampled at every vertex of every part (ParaView's "Resample With Dataset"; the
// renderers sample the volume itself at each point, VolumeFieldSampler, and these values give the
// default range):
// a point field "@NAME" per volume (its name, else "volume N"), trilinear as the renderers sample
// it, NaN farther than half a voxel outside its box (within it: the nearest face's value) — so a surface can be
// coloured by the volume it lies in. Each part with a volume gets a mesh of its own; a part that has the field already
// keeps it. Loading a scene (loadScene, .mfrscene files before their "color_by") calls it.
void addVolumeFields(Scene& scene);

// A surface coloured by a volume ("@NAME", addVolumeFields' names) takes the volume's value at each
// of its points, not its vertices' values interpolated: a section cap or a large triangle through
// the volume shows the samples inside it (ParaView's slice), not a blend of its rim. The GPU samples
// per fragment (common/fragment.glsl) exactly as `at` does for the oracle and the probe.
struct VolumeFieldSampler {
  std::shared_ptr<const VolumeGrid> grid;
  glm::dmat4 objectToGrid{1.0};  // the object's transform, then world → grid coordinates
  // Trilinear (VolumeGrid::sample); NaN farther than half a voxel outside the grid's box (within
  // it: the nearest face's value).
  [[nodiscard]] float at(const glm::dvec3& objectPoint) const;
  // `volume` seen from an object placed by `objectTransform`.
  [[nodiscard]] static VolumeFieldSampler of(const Volume& volume, const glm::dmat4& objectTransform);
  // The point field `name`: `at` each of the mesh's vertices.
  [[nodiscard]] MeshField atVertices(const std::string& name, const Mesh& mesh) const;
};
// The field name "@NAME" of the scene's volume v (its name, else "volume v").
std::string volumeFieldName(const Scene& scene, std::size_t v);
// Why `field` ("@NAME") cannot say which volume it means — more than one has that name (a file
// listed twice without names) —, or nothing when it can.
std::optional<std::string> ambiguousVolumeField(const Scene& scene, const std::string& field);
// The sampler of the volume `object` is coloured by (Material::fieldColors names one of the
// scene's volumes and the mesh has its vertex samples, which give the default range); else null.
std::optional<VolumeFieldSampler> volumeFieldSampler(const Scene& scene, const Object& object);

// Whether the mesh has the array `field` names ("name", or the array before ":N" / ":magnitude").
bool hasField(const Mesh& mesh, const std::string& field);

// The range colorObjectsByField gives `field` by default: the union of its finite values over the
// meshes that have it (fieldRange's rules when that is empty). Meshes without it are passed over.
glm::dvec2 sharedFieldRange(const std::vector<const Mesh*>& meshes, const std::string& field);

// colorByField on every object whose mesh has the field (hasField), all with one range: `range`, or
// the field's range over all of them (as ParaView maps a multi-block dataset). Returns how many it
// coloured; none is FieldNotFound(what, …) listing the fields the objects have. Other refusals as
// colorByField's (an unknown map, a bad range, a component the array lacks).
std::size_t colorObjectsByField(const std::vector<Object*>& objects, const std::string& field, const std::string& map,
                                const std::optional<glm::dvec2>& range, const std::string& what);

}  // namespace mfr
