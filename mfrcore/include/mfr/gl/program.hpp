#pragma once
// Shader programs built from files under shaders/ (embedded in the binary at build time; the
// environment variable MFR_SHADER_DIR makes them load from a folder instead, for editing).
// Sources may use #include "path" (relative to shaders/) and receive injected #defines.
// Compile errors are reported as "shaders/<file>:<line>: <message>".
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/gl/objects.hpp"

namespace mfr::gl {

using Defines = std::map<std::string, std::string>;

struct ShaderStage {
  GLenum type;       // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER, …
  std::string path;  // relative to shaders/
};

// Text of a shader file (embedded, or from MFR_SHADER_DIR). Throws mfr::Error if unknown.
std::string shaderSource(const std::string& path);

// Expands #include "…" recursively (each file once) and inserts "#version 450 core", the
// defines and #line directives. fileNames receives the file of each GLSL source-string number.
std::string preprocessShader(const std::string& path, const Defines& defines,
                             std::vector<std::string>* fileNames = nullptr);

class Program {
 public:
  Program() = default;
  Program(const std::vector<ShaderStage>& stages, const Defines& defines = {});
  Program(Program&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  Program& operator=(Program&& o) noexcept {
    if (this != &o) {
      if (id_ != 0) glDeleteProgram(id_);
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  [[nodiscard]] GLuint id() const { return id_; }
  void use() const;
  // Uniform setters by name; a name the linker removed is ignored.
  void set(const char* name, int v) const;
  void set(const char* name, unsigned v) const;
  void set(const char* name, float v) const;
  void set(const char* name, const glm::vec2& v) const;
  void set(const char* name, const glm::vec3& v) const;
  void set(const char* name, const glm::vec4& v) const;
  void set(const char* name, const glm::ivec2& v) const;
  void set(const char* name, const glm::ivec3& v) const;
  void set(const char* name, const glm::mat4& v) const;
  void set(const char* name, const glm::mat3& v) const;
  // A uint array uniform from its first element on.
  void set(const char* name, std::span<const std::uint32_t> v) const;

 private:
  GLint location(const char* name) const;
  GLuint id_ = 0;
};

}  // namespace mfr::gl
