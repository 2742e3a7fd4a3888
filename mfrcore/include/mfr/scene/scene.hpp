#pragma once
// A scene: objects (mesh + transform + material), volumes, named views and a background.
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/camera.hpp"
#include "mfr/scene/csg.hpp"
#include "mfr/scene/mesh.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr {

// Colouring a surface by a field of its mesh (ParaView's "Color by"): the colour map turns each
// value of Mesh::scalars, taken at a point of a triangle by interpolating its corners' values,
// into the colour there. Set by colorByField (scene/color_map.hpp).
struct FieldColors {
  std::string field;              // what Mesh::scalars holds: "name", "name:N" or "name:magnitude"
  std::string map = "cool-warm";  // colorMapNames()
  glm::dvec2 range{0.0, 1.0};     // the values mapped to the map's two ends (clamped outside)
  bool operator==(const FieldColors&) const = default;
};

struct Material {
  glm::vec4 color{0.8f, 0.8f, 0.8f, 0.5f};  // RGB display values in [0,1], A = opacity
  // Whether the mesh's per-vertex colours (Mesh::colors) multiply `color`. False once the part is
  // given a colour of its own (a scene file's "color", the viewer's colour picker): `color` then
  // replaces the file's colours, as it does for meshes without any.
  bool vertexColors = true;
  // Set: the colour map of the mesh's scalars replaces `color`'s RGB and the vertex colours;
  // `color.a` stays the opacity.
  std::optional<FieldColors> fieldColors;
  bool operator==(const Material&) const = default;
};

struct Object {
  std::string name;
  std::shared_ptr<const Mesh> mesh;  // shared: CAD assemblies instance one mesh many times
  glm::dmat4 transform{1.0};         // object → world
  Material material;
  bool visible = true;
};

// What turns an object's normals into the world's: the inverse transpose of the transform's linear
// part, scaled by a power of two to a largest entry in [1, 2) when that entry lies beyond 2^±20.
// Only directions are taken from it, and unscaled a transform of scale 1e-19 made entries of 1e19,
// whose normals overflowed in float when normalised (shading came out wrong, and differently on the
// GPU and in the oracle; a bug hunt).
glm::dmat3 normalMatrix(const glm::dmat4& transform);

// A section plane (world space): what lies on the side its normal points to is kept, the rest is
// cut away. With caps, every closed surface it cuts is closed again by the cross-section, so solids
// look solid (the CAD section view); open surfaces are only cut. (.mfrscene "section",
// mfr render --section, mfrview's Clip dock; scene/section.hpp does the cutting.)
struct SectionPlane {
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 0.0, 1.0};  // need not be unit length; never zero
  bool caps = true;
  // Each volume's slice: the plane's cross-section of the volume's box as a part "NAME slice",
  // opaque, coloured by the volume at each point (grayscale over its transfer function's range) —
  // ParaView's Slice of an image, a CT viewer's plane (sectionedScene).
  bool slice = false;
  bool operator==(const SectionPlane&) const = default;
};

struct NamedView {
  std::string name;
  Camera camera;
};

struct Scene {
  // The most volumes drawn at once (MFR_MAX_VOLUMES in shaders/common/bindings.h: texture units).
  static constexpr std::size_t kMaxVisibleVolumes = 4;

  std::string name;  // file name or sample name, for messages
  std::vector<Object> objects;
  std::vector<NamedView> views;  // the scene's own views; "fit" is always available besides
  glm::vec3 background{1.0f, 1.0f, 1.0f};
  CsgTree csg;  // image-space CSG over some objects (operation "csg"); empty: none
  // Scalar volumes composited with the surfaces by the operation "volume"; at most MFR_MAX_VOLUMES
  // (kMaxVisibleVolumes) visible, marched together (overlapping media mix).
  std::vector<Volume> volumes;
  // The clip box (world space): only what lies inside it is drawn — surfaces are cut open along its
  // faces, the volume is cropped — by every method and by the oracle. Unset: nothing is clipped.
  // bounds() and fit() ignore it, so a view frames the whole scene and the cut shows in place.
  // (.mfrscene "clip", mfr render --clip, mfrview's Clip box.)
  std::optional<Bounds> clipBox;
  // The section plane: both renderers draw sectionedScene(*this) (scene/section.hpp) — surfaces cut
  // and capped as geometry, the volume cropped to the kept side. Unset: no section. bounds() and
  // fit() ignore it, like the clip box.
  std::optional<SectionPlane> section;
  bool sectionCut = false;  // the meshes are sectionedScene's: already cut by `section`
  // sectionedScene's copy keeps the whole scene's bounds() and boundingRadius(), so that its fit,
  // orbit views and default z-thickness are the uncut scene's, as said above (its cut meshes would
  // frame the kept part and give a thinner default slab).
  std::optional<std::pair<Bounds, double>> uncutExtent;
  // What loading could not do as asked but is no error (LoadOptions::notes), one line each.
  std::vector<std::string> notes;

  [[nodiscard]] Bounds bounds() const;  // world bounds of visible objects and volumes
  // Radius of the smallest sphere around bounds().center() holding every visible vertex and
  // volume corner.
  [[nodiscard]] double boundingRadius() const;
  // Camera with the direction and up of `base`, framing the visible objects.
  [[nodiscard]] Camera fit(const Camera& base) const;
  [[nodiscard]] std::size_t triangleCount() const;
  // Object ids are indices into objects; GPU and oracle both report them.
  // Copies of the visible volumes (sharing their grids), in the order of `volumes`.
  [[nodiscard]] std::vector<Volume> visibleVolumes() const;
  [[nodiscard]] bool hasVisibleVolume() const;
  // Throws mfr::Error when there is nothing visible to draw (no triangles, no volume), when more
  // than kMaxVisibleVolumes volumes are visible, or for an invalid volume.
  void validate() const;
  // The named view, or the fit-all view for "fit" / empty name. Every scene has "front" (from +Z)
  // and "iso" (from (1, 0.8, 1)), fit-all, unless it has views of those names of its own (a scene
  // file's "views", @quads's orthographic front). Throws mfr::Error listing the available names for
  // an unknown one.
  [[nodiscard]] Camera view(const std::string& name) const;
  [[nodiscard]] std::vector<std::string> viewNames() const;
  // The fit-all "front" or "iso" view; nullopt for any other name.
  [[nodiscard]] std::optional<Camera> standardView(const std::string& name) const;
};

// A clip box as `mfr render --clip` and `mfrview --clip` take it: six numbers
// xmin,ymin,zmin,xmax,ymax,zmax. Throws mfr::Error(what, reason) for anything else or min > max.
Bounds parseClipBox(const std::string& text, const std::string& what);
// Throws mfr::Error(what, …) for a clip box with a non-finite corner or min > max on an axis.
void validateClipBox(const std::optional<Bounds>& box, const std::string& what);
// Throws mfr::Error(what, …) for a section plane with a non-finite point or normal or a zero normal.
void validateSectionPlane(const std::optional<SectionPlane>& plane, const std::string& what);
// Whether world point p is drawn under the clip box (always without one); the box's faces count
// as inside.
bool insideClipBox(const std::optional<Bounds>& box, const glm::dvec3& p);

}  // namespace mfr
