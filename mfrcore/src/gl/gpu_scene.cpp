#include "mfr/gl/gpu_scene.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "common/bindings.h"
#include "grid_upload.hpp"
#include "mfr/scene/color_map.hpp"

namespace mfr::gl {
namespace {
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec4 color;
  float scalar;
};

// Every colour map's table, one row each (common/color_map.glsl).
Texture colorMapTexture() {
  const std::vector<std::string>& names = colorMapNames();
  const int width = MFR_COLOR_MAP_SIZE + 1, height = static_cast<int>(names.size());
  std::vector<glm::vec4> texels;
  texels.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (const std::string& name : names) {
    const ColorMap& map = colorMap(name);
    for (const glm::vec3& c : map.table) texels.emplace_back(c, 1.0f);
    texels.emplace_back(map.nanColor, 1.0f);
  }
  Texture t = createTexture2D(GL_RGBA32F, width, height);
  glTextureSubImage2D(t.id(), 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, texels.data());
  return t;
}
}  // namespace

GpuScene::GpuScene(const Scene& scene, const GpuScene* previous,
                   const std::function<std::shared_ptr<Texture>(const VolumeGrid*)>& knownGrid) {
  colorMaps_ = colorMapTexture();
  std::map<const Mesh*, std::shared_ptr<const GpuMesh>> before;
  if (previous)
    for (const std::shared_ptr<const GpuMesh>& g : previous->meshes_) before.emplace(g->source.get(), g);
  std::map<const Mesh*, std::size_t> uploaded;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    if (!o.visible || !o.mesh || o.mesh->triangleCount() == 0) continue;
    auto [it, isNew] = uploaded.try_emplace(o.mesh.get(), meshes_.size());
    if (isNew) {
      if (const auto shared = before.find(o.mesh.get()); shared != before.end()) {
        meshes_.push_back(shared->second);
      } else {
        const Mesh& m = *o.mesh;
        auto g = std::make_shared<GpuMesh>();
        // Relative to the mesh's own centre, so that a mesh far from its origin keeps its detail.
        if (const Bounds b = m.bounds(); b.valid()) g->centre = b.center();
        std::vector<Vertex> v(m.positions.size());
        for (std::size_t k = 0; k < v.size(); ++k)
          v[k] = {glm::vec3(glm::dvec3(m.positions[k]) - g->centre),
                  m.normals.empty() ? glm::vec3(0, 0, 1) : m.normals[k],
                  m.colors.empty() ? glm::vec4(1.0f) : m.colors[k], m.scalars.empty() ? 0.0f : m.scalars[k]};
        g->source = o.mesh;
        g->vertices = createBuffer(v.size() * sizeof(Vertex), v.data(), 0);
        g->indices = createBuffer(m.indices.size() * sizeof(std::uint32_t), m.indices.data(), 0);
        g->indexCount = static_cast<GLsizei>(m.indices.size());
        g->vao = createVertexArray();
        const GLuint vao = g->vao.id();
        glVertexArrayVertexBuffer(vao, 0, g->vertices.id(), 0, sizeof(Vertex));
        glVertexArrayElementBuffer(vao, g->indices.id());
        const auto attrib = [&](GLuint loc, GLint n, std::size_t offset) {
          glEnableVertexArrayAttrib(vao, loc);
          glVertexArrayAttribFormat(vao, loc, n, GL_FLOAT, GL_FALSE, static_cast<GLuint>(offset));
          glVertexArrayAttribBinding(vao, loc, 0);
        };
        attrib(MFR_ATTR_POSITION, 3, offsetof(Vertex, position));
        attrib(MFR_ATTR_NORMAL, 3, offsetof(Vertex, normal));
        attrib(MFR_ATTR_COLOR, 4, offsetof(Vertex, color));
        attrib(MFR_ATTR_SCALAR, 1, offsetof(Vertex, scalar));
        g->bytes = v.size() * sizeof(Vertex) + m.indices.size() * sizeof(std::uint32_t);
        uploaded_ += g->bytes;
        meshes_.push_back(std::move(g));
      }
      bytes_ += meshes_.back()->bytes;
    }
    // Mesh centre → world, composed in double; draw() makes it relative to the eye.
    const glm::dvec3 centre = meshes_[it->second]->centre;
    const glm::dmat4 toMesh = glm::translate(glm::dmat4(1.0), centre);
    const glm::dmat4 model = o.transform * toMesh;
    // A field colouring needs the field's values on the mesh (colorByField puts them there).
    const std::optional<FieldColors>& field = o.material.fieldColors;
    const bool mapped = field && o.mesh->scalars.size() == o.mesh->positions.size();
    // Vertex colours only where the mesh has them (else white ones were uploaded): the shader then
    // reads the material's colour exactly, as the oracle does (common/fragment.glsl says why).
    const bool vertexColors = o.material.vertexColors && o.mesh->colors.size() == o.mesh->positions.size();
    items_.push_back({it->second, model, glm::mat3(normalMatrix(o.transform)), o.material.color, vertexColors,
                      static_cast<std::uint32_t>(i), mapped ? colorMapIndex(field->map) : -1,
                      mapped ? glm::vec2(field->range) : glm::vec2(0.0f, 1.0f)});
    if (const std::optional<VolumeFieldSampler> sampler = volumeFieldSampler(scene, o)) {
      DrawItem& item = items_.back();
      const VolumeGrid* grid = sampler->grid.get();
      auto known = std::find_if(fieldGrids_.begin(), fieldGrids_.end(),
                                [&](const FieldGrid& f) { return f.source.get() == grid; });
      if (known == fieldGrids_.end()) {
        std::shared_ptr<Texture> texture = previous ? previous->fieldGrid(grid) : nullptr;
        if (!texture && knownGrid) texture = knownGrid(grid);
        if (!texture) {
          texture = uploadGrid(sampler->grid);
          uploaded_ += grid->values.size() * sizeof(float);
        }
        fieldGrids_.push_back({sampler->grid, std::move(texture)});
        bytes_ += grid->values.size() * sizeof(float);
        known = fieldGrids_.end() - 1;
      }
      item.fieldGrid = static_cast<int>(known - fieldGrids_.begin());
      item.fieldToGrid = glm::mat4(sampler->objectToGrid * toMesh);
      // The samples are uploaded scaled (uploadGrid): so is the range the map compares them with.
      if (const double scale = gridValueScale(sampler->grid); scale != 1.0)
        item.colorMapRange = glm::vec2(glm::dvec2(field->range) * scale);
    }
    triangles_ += o.mesh->triangleCount();
  }
}

std::shared_ptr<Texture> GpuScene::fieldGrid(const VolumeGrid* grid) const {
  for (const FieldGrid& f : fieldGrids_)
    if (f.source.get() == grid) return f.texture;
  return nullptr;
}

FrameUniforms GpuScene::relativeFrame(const glm::dmat4& viewProj, const std::optional<Bounds>& clipBox,
                                      const glm::dvec3& origin) {
  FrameUniforms frame;
  frame.origin =
      std::isfinite(origin.x) && std::isfinite(origin.y) && std::isfinite(origin.z) ? origin : glm::dvec3(0.0);
  frame.viewProj = glm::mat4(viewProj * glm::translate(glm::dmat4(1.0), frame.origin));
  if (clipBox) {
    frame.clip = true;
    frame.clipMin = glm::vec3(clipBox->min - frame.origin);
    frame.clipMax = glm::vec3(clipBox->max - frame.origin);
  }
  return frame;
}

void GpuScene::draw(const Program& program, const FrameUniforms& frame) const {
  program.use();
  program.set("uViewProj", frame.viewProj);
  program.set("uViewDir", frame.viewDir);
  program.set("uPayload", frame.payload);
  program.set("uClipMin", frame.clipMin);
  program.set("uClipMax", frame.clipMax);
  glBindTextureUnit(MFR_TEX_COLOR_MAPS, colorMaps_.id());
  // Six planes, enabled only while this draw runs (full-screen passes write no clip distances).
  for (int i = 0; i < 6; ++i) {
    if (frame.clip)
      glEnable(GL_CLIP_DISTANCE0 + static_cast<GLenum>(i));
    else
      glDisable(GL_CLIP_DISTANCE0 + static_cast<GLenum>(i));
  }
  for (const DrawItem& item : items_) {
    const GpuMesh& m = *meshes_[item.mesh];
    glm::dmat4 model = item.model;  // world → relative to frame.origin: a translation, in double
    model[3] -= glm::dvec4(frame.origin, 0.0);
    program.set("uModel", glm::mat4(model));
    program.set("uNormalMatrix", item.normalMatrix);
    program.set("uColor", item.color);
    program.set("uVertexColors", item.vertexColors ? 1 : 0);
    program.set("uObjectId", item.objectId);
    program.set("uColorMapRow", item.colorMapRow);
    program.set("uColorMapRange", item.colorMapRange);
    program.set("uFieldGrid", item.fieldGrid >= 0 ? 1 : 0);
    program.set("uFieldToGrid", item.fieldToGrid);
    if (item.fieldGrid >= 0) {
      const FieldGrid& grid = fieldGrids_[static_cast<std::size_t>(item.fieldGrid)];
      program.set("uFieldGridDims", grid.source->dims);
      glBindTextureUnit(MFR_TEX_FIELD_GRID, grid.texture->id());
    }
    glBindVertexArray(m.vao.id());
    glDrawElements(GL_TRIANGLES, m.indexCount, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
  if (frame.clip)
    for (int i = 0; i < 6; ++i) glDisable(GL_CLIP_DISTANCE0 + static_cast<GLenum>(i));
}

}  // namespace mfr::gl
