#include "mfr/gl/objects.hpp"

#include <algorithm>
#include <cstdint>
#include <string_view>

#include "mfr/host_memory.hpp"

namespace mfr::gl {

namespace {

// A software rasteriser keeps "GPU" storage in this process's memory, where Linux overcommits: an
// allocation past the machine's memory succeeds and the process is killed when it is touched. A
// hardware driver reports GL_OUT_OF_MEMORY itself (checkErrors turns it into an mfr::Error).
// Each allocation is checked on its own; the checks add up because llvmpipe zero-fills storage as
// it creates it (measured: RSS grows by the size at glNamedBufferStorage), so earlier buffers are
// already resident and counted (test: GlInfrastructure.SoftwareStorageCountsTogether…).
bool storageInHostMemory() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (renderer == nullptr) return false;
  const std::string_view name(renderer);
  for (const std::string_view software : {"llvmpipe", "softpipe", "swrast", "Software Rasterizer"})
    if (name.find(software) != std::string_view::npos) return true;
  return false;
}

void requireStorage(std::uint64_t bytes) {
  if (bytes >= (std::uint64_t{16} << 20) && storageInHostMemory())
    requireHostMemory("OpenGL", "a GPU buffer of the software rasteriser (in main memory)", bytes);
}

std::uint64_t texelBytes(GLenum internalFormat) {
  switch (internalFormat) {
    case GL_R8:
      return 1;
    case GL_R16F:
      return 2;
    case GL_RGBA8:
    case GL_R32F:
    case GL_R32UI:
    case GL_DEPTH_COMPONENT32F:
      return 4;
    case GL_RGBA16F:
    case GL_RG32F:
    case GL_RG32UI:
      return 8;
    case GL_RGBA32F:  // NOLINT(bugprone-branch-clone): named, not left to the guess below
      return 16;
    default:
      return 16;  // the largest colour format: a conservative guess
  }
}

std::uint64_t texels(int width, int height = 1, int depth = 1) {
  return static_cast<std::uint64_t>(std::max(width, 0)) * static_cast<std::uint64_t>(std::max(height, 0)) *
         static_cast<std::uint64_t>(std::max(depth, 0));
}

}  // namespace

Buffer createBuffer(std::size_t bytes, const void* data, GLbitfield flags) {
  requireStorage(bytes);
  GLuint id = 0;
  glCreateBuffers(1, &id);
  // Zero-size storage is invalid in GL: allocate at least 4 bytes so bindings stay valid.
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes > 0 ? bytes : 4), bytes > 0 ? data : nullptr, flags);
  return Buffer(id);
}

Texture createTexture2D(GLenum internalFormat, int width, int height) {
  requireStorage(texels(width, height) * texelBytes(internalFormat));
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, 1, internalFormat, width, height);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return Texture(id);
}

Texture createTexture1D(GLenum internalFormat, int width) {
  requireStorage(texels(width) * texelBytes(internalFormat));
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_1D, 1, &id);
  glTextureStorage1D(id, 1, internalFormat, width);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  return Texture(id);
}

Texture createTexture3D(GLenum internalFormat, int width, int height, int depth) {
  requireStorage(texels(width, height, depth) * texelBytes(internalFormat));
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_3D, 1, &id);
  glTextureStorage3D(id, 1, internalFormat, width, height, depth);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  return Texture(id);
}

VertexArray createVertexArray() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return VertexArray(id);
}

Framebuffer createFramebuffer() {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  return Framebuffer(id);
}

Query createQuery(GLenum target) {
  GLuint id = 0;
  glCreateQueries(target, 1, &id);
  return Query(id);
}

}  // namespace mfr::gl
