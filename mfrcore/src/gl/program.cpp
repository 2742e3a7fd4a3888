#include "mfr/gl/program.hpp"

#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <glm/gtc/type_ptr.hpp>

#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"

namespace mfr::gl {
namespace detail {
const std::map<std::string, std::string_view, std::less<>>& embeddedShaders();  // generated
}

std::string shaderSource(const std::string& path) {
  if (const char* dir = std::getenv("MFR_SHADER_DIR"); dir && *dir) {
    std::ifstream in(std::string(dir) + "/" + path, std::ios::binary);
    if (!in) throw Error("shaders/" + path, std::string("not found in MFR_SHADER_DIR=") + dir);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  const auto& files = detail::embeddedShaders();
  const auto it = files.find(path);
  if (it == files.end()) throw Error("shaders/" + path, "no such shader");
  return std::string(it->second);
}

namespace {

void expand(const std::string& path, const Defines& defines, std::vector<std::string>& files,
            std::set<std::string>& included, std::string& out, int depth) {
  if (depth > 32) throw Error("shaders/" + path, "#include nested too deeply");
  if (!included.insert(path).second) return;  // each file once: includes need no guards
  const int index = static_cast<int>(files.size());
  files.push_back(path);
  std::istringstream in(shaderSource(path));
  // #include "path", or #include NAME where NAME is an injected define holding "path" (this is how
  // a resolve pass receives its operation).
  static const std::regex includeLine(R"re(^\s*#\s*include\s+(?:"([^"]+)"|([A-Za-z_][A-Za-z0-9_]*))\s*$)re");
  static const std::regex versionLine(R"(^\s*#\s*version\b.*$)");
  out += "#line 1 " + std::to_string(index) + "\n";
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    std::smatch m;
    if (std::regex_match(line, m, includeLine)) {
      std::string target = m[1].str();
      if (target.empty()) {
        const auto d = defines.find(m[2].str());
        if (d == defines.end())
          throw Error("shaders/" + path + ":" + std::to_string(lineNo), "#include of undefined name " + m[2].str());
        target = d->second;
        if (target.size() >= 2 && target.front() == '"' && target.back() == '"')
          target = target.substr(1, target.size() - 2);
      }
      expand(target, defines, files, included, out, depth + 1);
      out += "#line " + std::to_string(lineNo + 1) + " " + std::to_string(index) + "\n";
    } else if (std::regex_match(line, versionLine)) {
      out += "\n";  // the preprocessor writes the one #version line
    } else {
      out += line + "\n";
    }
  }
}

// Rewrites "0:12(3): error" (Mesa) and "0(12) : error" (NVIDIA) into "shaders/<file>:12: error".
std::string mapLog(const std::string& log, const std::vector<std::string>& files) {
  static const std::regex mesa(R"((\d+):(\d+)\(\d+\):\s*)");
  static const std::regex nvidia(R"((\d+)\((\d+)\)\s*:\s*)");
  std::string out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, mesa) || std::regex_search(line, m, nvidia)) {
      const auto idx = static_cast<std::size_t>(std::stoul(m[1].str()));
      const std::string file = idx < files.size() ? "shaders/" + files[idx] : "?";
      line = m.prefix().str() + file + ":" + m[2].str() + ": " + m.suffix().str();
    }
    if (!line.empty()) out += (out.empty() ? "" : " | ") + line;
  }
  return out;
}

}  // namespace

std::string preprocessShader(const std::string& path, const Defines& defines, std::vector<std::string>* fileNames) {
  std::string out = "#version 450 core\n";
  // Extensions must precede all code: shaders ask for them via MFR_EXTENSION_* defines.
  for (const auto& [name, value] : defines)
    if (name.rfind("#extension", 0) == 0) out += name + " : " + value + "\n";
  out += "#define MFR_GLSL 1\n";
  for (const auto& [name, value] : defines)
    if (name.rfind("#extension", 0) != 0) out += "#define " + name + " " + value + "\n";
  std::vector<std::string> files;
  std::set<std::string> included;
  expand(path, defines, files, included, out, 0);
  if (fileNames) *fileNames = std::move(files);
  return out;
}

Program::Program(const std::vector<ShaderStage>& stages, const Defines& defines) {
  id_ = glCreateProgram();
  std::vector<GLuint> shaders;
  const auto cleanup = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  for (const ShaderStage& stage : stages) {
    std::vector<std::string> files;
    std::string source;
    try {
      source = preprocessShader(stage.path, defines, &files);
    } catch (...) {
      cleanup();
      glDeleteProgram(id_);
      id_ = 0;
      throw;
    }
    const GLuint shader = glCreateShader(stage.type);
    shaders.push_back(shader);
    const char* src = source.c_str();
    glShaderSource(shader, 1, &src, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      GLint len = 0;
      glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
      std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
      glGetShaderInfoLog(shader, len, nullptr, log.data());
      cleanup();
      glDeleteProgram(id_);
      id_ = 0;
      discardErrors();  // the compile log says it all; drop the debug copy
      throw Error("shaders/" + stage.path, "compile error: " + mapLog(log.c_str(), files));
    }
    glAttachShader(id_, shader);
  }
  glLinkProgram(id_);
  cleanup();
  GLint ok = GL_FALSE;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetProgramInfoLog(id_, len, nullptr, log.data());
    glDeleteProgram(id_);
    id_ = 0;
    std::string names;
    for (const ShaderStage& s : stages) names += (names.empty() ? "" : "+") + s.path;
    throw Error("shaders/" + names, "link error: " + mapLog(log.c_str(), {}));
  }
}

Program::~Program() {
  if (id_ != 0) glDeleteProgram(id_);
}

void Program::use() const {
  glUseProgram(id_);
}

GLint Program::location(const char* name) const {
  return glGetUniformLocation(id_, name);
}

void Program::set(const char* name, int v) const {
  glProgramUniform1i(id_, location(name), v);
}
void Program::set(const char* name, unsigned v) const {
  glProgramUniform1ui(id_, location(name), v);
}
void Program::set(const char* name, float v) const {
  glProgramUniform1f(id_, location(name), v);
}
void Program::set(const char* name, const glm::vec2& v) const {
  glProgramUniform2fv(id_, location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::vec3& v) const {
  glProgramUniform3fv(id_, location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::vec4& v) const {
  glProgramUniform4fv(id_, location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::ivec2& v) const {
  glProgramUniform2iv(id_, location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::ivec3& v) const {
  glProgramUniform3iv(id_, location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::mat4& v) const {
  glProgramUniformMatrix4fv(id_, location(name), 1, GL_FALSE, glm::value_ptr(v));
}
void Program::set(const char* name, std::span<const std::uint32_t> v) const {
  glProgramUniform1uiv(id_, location(name), static_cast<GLsizei>(v.size()), v.data());
}
void Program::set(const char* name, const glm::mat3& v) const {
  glProgramUniformMatrix3fv(id_, location(name), 1, GL_FALSE, glm::value_ptr(v));
}

}  // namespace mfr::gl
