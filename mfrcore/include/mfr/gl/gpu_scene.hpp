#pragma once
// A scene uploaded to the GPU: one vertex/index buffer pair per distinct mesh, drawn object by
// object with the per-object uniforms every capture shader receives through
// shaders/common/scene.vert (uModel, uNormalMatrix, uColor, uVertexColors, uObjectId) and
// common/color_map.glsl (uColorMapRow, uColorMapRange) and common/fragment.glsl (a volume that
// colours the surface: uFieldGrid, uFieldToGrid, uFieldGridDims and its grid's texture), plus the
// per-frame uViewProj and uViewDir.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/gl/objects.hpp"
#include "mfr/gl/program.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::gl {

struct FrameUniforms {
  // The world point the GPU's coordinates are relative to: a point of the view axis where what is
  // seen is drawn finest (GpuRenderer's floatOrigin). viewProj and clipMin/clipMax
  // are relative to it (GpuScene::relativeFrame), and so is each part's model matrix (draw()).
  glm::dvec3 origin{0.0};
  glm::mat4 viewProj{1.0f};
  glm::vec3 viewDir{0.0f, 0.0f, -1.0f};  // headlight direction (camera forward), world space
  int payload = 0;  // what capture passes store in a fragment's colour word: MFR_PAYLOAD_* (bindings.h)
  // Scene::clipBox: draw() clips every triangle to it with six clip distances (common/scene.vert).
  // Without a box the faces lie far outside any scene: llvmpipe clips by written distances even
  // with GL_CLIP_DISTANCEi disabled, so they must be positive either way.
  bool clip = false;
  glm::vec3 clipMin{-1e30f};
  glm::vec3 clipMax{1e30f};
};

class GpuScene {
 public:
  // `previous`: a scene uploaded before in the same context. Meshes it holds that this scene still
  // draws (the same Mesh objects: an edit of colours, visibility, transforms, the clip box or a
  // section that leaves a part uncut keeps them) are shared with it, not uploaded again.
  // `knownGrid`: textures of volume grids the caller holds already (its volume operation's), used for
  // a surface coloured by that volume instead of a second upload; previous's are used likewise.
  explicit GpuScene(const Scene& scene, const GpuScene* previous = nullptr,
                    const std::function<std::shared_ptr<Texture>(const VolumeGrid*)>& knownGrid = {});
  // Draws every visible object with program (already configured by the caller: state, buffers).
  void draw(const Program& program, const FrameUniforms& frame) const;
  [[nodiscard]] std::size_t triangleCount() const { return triangles_; }
  [[nodiscard]] std::size_t bytes() const { return bytes_; }             // of every mesh it draws, shared or not
  [[nodiscard]] std::size_t uploadedBytes() const { return uploaded_; }  // of the meshes it uploaded itself
  // The texture (R32F) of a volume grid that colours a surface here (mfr::VolumeFieldSampler), else
  // null: the renderer's volume operation uses it rather than upload the grid twice.
  [[nodiscard]] std::shared_ptr<Texture> fieldGrid(const VolumeGrid* grid) const;
  // `viewProj` (world → clip, double) and the scene's clip box as draw() needs them: relative to
  // `origin`, in float. Positions far from the world's origin (survey coordinates, 1e6 and beyond)
  // lost their float precision in the view transform: a unit cube at 1e7 was RMSE 0.16 from the
  // oracle (a bug hunt); relative to the scene's centre, a part 1e-4 in size 40 units from it, or
  // beside the eye of a scene reaching 1e6 away, was drawn jagged and mis-sorted (hunt 31). The
  // renderer takes the origin on the view axis where what is seen is drawn finest
  // (GpuRenderer's floatOrigin), so what the GPU computes in float is small where it matters.
  [[nodiscard]] static FrameUniforms relativeFrame(const glm::dmat4& viewProj, const std::optional<Bounds>& clipBox,
                                                   const glm::dvec3& origin);

 private:
  struct GpuMesh {
    std::shared_ptr<const Mesh> source;  // kept alive, so that its address names it while shared
    VertexArray vao;
    Buffer vertices;
    Buffer indices;
    GLsizei indexCount = 0;
    std::size_t bytes = 0;
    glm::dvec3 centre{0.0};  // of the mesh's bounds: its vertices are uploaded relative to it
  };
  struct DrawItem {
    std::size_t mesh;
    glm::dmat4 model;  // mesh (relative to its centre) → world, in double: draw() makes it relative to the eye
    glm::mat3 normalMatrix;
    glm::vec4 color;
    bool vertexColors;
    std::uint32_t objectId;
    int colorMapRow;  // Material::fieldColors' map (colorMapIndex); -1: not field-coloured
    glm::vec2 colorMapRange;
    // Coloured by a volume: its grid's index in fieldGrids_, object → grid coordinates; else -1.
    int fieldGrid = -1;
    glm::mat4 fieldToGrid{1.0f};
  };
  struct FieldGrid {
    std::shared_ptr<const VolumeGrid> source;  // kept alive, so that its address names it while shared
    std::shared_ptr<Texture> texture;
  };
  std::vector<std::shared_ptr<const GpuMesh>> meshes_;
  std::vector<FieldGrid> fieldGrids_;
  std::vector<DrawItem> items_;
  Texture colorMaps_;  // every colour map's table (common/color_map.glsl), bound while drawing
  std::size_t triangles_ = 0;
  std::size_t bytes_ = 0;
  std::size_t uploaded_ = 0;
};

}  // namespace mfr::gl
