#pragma once
// RAII owners of GL object names. Move-only; the destructor deletes the name.
#include <cstddef>
#include <utility>

#include <epoxy/gl.h>

namespace mfr::gl {

template <void (*Delete)(GLuint)>
class Handle {
 public:
  Handle() = default;
  explicit Handle(GLuint id) : id_(id) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  [[nodiscard]] GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_ != 0) Delete(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace detail {
inline void deleteBuffer(GLuint id) {
  glDeleteBuffers(1, &id);
}
inline void deleteTexture(GLuint id) {
  glDeleteTextures(1, &id);
}
inline void deleteFramebuffer(GLuint id) {
  glDeleteFramebuffers(1, &id);
}
inline void deleteVertexArray(GLuint id) {
  glDeleteVertexArrays(1, &id);
}
inline void deleteQuery(GLuint id) {
  glDeleteQueries(1, &id);
}
inline void deleteProgram(GLuint id) {
  glDeleteProgram(id);
}
inline void deleteShader(GLuint id) {
  glDeleteShader(id);
}
}  // namespace detail

using Buffer = Handle<detail::deleteBuffer>;
using Texture = Handle<detail::deleteTexture>;
using Framebuffer = Handle<detail::deleteFramebuffer>;
using VertexArray = Handle<detail::deleteVertexArray>;
using Query = Handle<detail::deleteQuery>;

Buffer createBuffer(std::size_t bytes, const void* data = nullptr, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
// Immutable 2D texture (glTextureStorage2D).
Texture createTexture2D(GLenum internalFormat, int width, int height);
// Immutable 1D and 3D textures, nearest filtering, clamped (read with texelFetch).
Texture createTexture1D(GLenum internalFormat, int width);
Texture createTexture3D(GLenum internalFormat, int width, int height, int depth);
VertexArray createVertexArray();
Framebuffer createFramebuffer();
Query createQuery(GLenum target);

}  // namespace mfr::gl
