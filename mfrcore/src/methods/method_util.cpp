#include "method_util.hpp"

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"

namespace mfr {

GeometryPassState::GeometryPassState(bool colorWrites, bool depthTest) {
  depthTest_ = glIsEnabled(GL_DEPTH_TEST);
  cull_ = glIsEnabled(GL_CULL_FACE);
  blend_ = glIsEnabled(GL_BLEND);
  glGetBooleanv(GL_COLOR_WRITEMASK, colorMask_);
  glGetBooleanv(GL_DEPTH_WRITEMASK, &depthMask_);
  if (depthTest)
    glEnable(GL_DEPTH_TEST);
  else
    glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  const GLboolean c = colorWrites ? GL_TRUE : GL_FALSE;
  glColorMask(c, c, c, c);
}

GeometryPassState::~GeometryPassState() {
  if (depthTest_)
    glEnable(GL_DEPTH_TEST);
  else
    glDisable(GL_DEPTH_TEST);
  if (cull_)
    glEnable(GL_CULL_FACE);
  else
    glDisable(GL_CULL_FACE);
  if (blend_)
    glEnable(GL_BLEND);
  else
    glDisable(GL_BLEND);
  glColorMask(colorMask_[0], colorMask_[1], colorMask_[2], colorMask_[3]);
  glDepthMask(depthMask_);
}

void runResolvePass(const FrameContext& ctx, const gl::Program& program, const Operation& op) {
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  program.use();
  program.set("uBackground", ctx.background);
  if (op.bind) op.bind(program);
  // Core profile draws need a vertex array object, even an empty one (the triangle is generated
  // from gl_VertexID).
  const gl::VertexArray empty = gl::createVertexArray();
  glBindVertexArray(empty.id());
  ctx.timer.begin("resolve");
  glDrawArrays(GL_TRIANGLES, 0, 3);
  ctx.timer.end();
  glBindVertexArray(0);
}

std::vector<std::uint32_t> readCapacities(const gl::Buffer& offsets, std::uint64_t pixels, std::uint64_t baseWord) {
  if (!offsets) return {};
  std::vector<std::uint32_t> raw(static_cast<std::size_t>(pixels) + 1, 0);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(offsets.id(), static_cast<GLintptr>(4 * baseWord), static_cast<GLsizeiptr>(raw.size() * 4),
                          raw.data());
  std::vector<std::uint32_t> k(static_cast<std::size_t>(pixels));
  for (std::size_t p = 0; p < k.size(); ++p) k[p] = raw[p + 1] - raw[p];
  return k;
}

std::uint64_t maxStorageElements(std::uint64_t elementBytes) {
  GLint64 maxBytes = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBytes);
  return static_cast<std::uint64_t>(maxBytes) / elementBytes;
}

void requireStorageFits(const std::string& what, const std::string& need, std::uint64_t count, std::uint64_t limit,
                        std::uint64_t elementBytes, const std::string& advice) {
  if (count <= limit) return;
  throw Error(what, need + " = " + formatMemory(count * elementBytes) +
                        ", more than the largest shader storage block of this GL context holds (" +
                        formatMemory(limit * elementBytes) + ")" + advice);
}

std::string depthTiesNote(std::uint64_t ties) {
  return std::to_string(ties) + (ties == 1 ? " fragment" : " fragments") +
         " at exactly the depth of a peeled layer, not composited (peeling keeps one fragment per depth)";
}

}  // namespace mfr
