#pragma once
// Headless OpenGL 4.5 core context through EGL: surfaceless on Mesa, the device platform where a
// driver (e.g. NVIDIA) offers no surfaceless platform. Renders go into FBOs.
#include <memory>
#include <string>

namespace mfr::gl {

struct ContextInfo {
  std::string vendor;
  std::string renderer;
  std::string version;
  std::string platform;  // "surfaceless" or "device"
  bool fragmentShaderInterlock = false;
  bool shaderInt64 = false;
};

class HeadlessContext {
 public:
  // Creates and makes current a 4.5 core context. debug: turn GL debug output into errors
  // (see checkErrors). Throws mfr::Error("OpenGL", reason) when no context can be created.
  explicit HeadlessContext(bool debug = true);
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  void makeCurrent();
  [[nodiscard]] const ContextInfo& info() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Installs the GL debug callback on the current context (used by HeadlessContext and by the Qt
// viewer's context). Messages of type error are recorded; checkErrors throws the first one.
void installDebugOutput();
// Throws mfr::Error("OpenGL", message) if the debug callback recorded an error or glGetError
// reports one since the last call; where names the pass or call site.
void checkErrors(const char* where);
// Forgets recorded errors (after an error already reported another way).
void discardErrors();
// Fills extension flags and strings of the current context.
ContextInfo queryContextInfo();

}  // namespace mfr::gl
