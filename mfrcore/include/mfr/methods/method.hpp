#pragma once
// The interface every multifragment construction method implements (A-buffers, depth peeling,
// k-buffers, …): configure → capture → resolve with an operation → Stats. A method and an
// operation meet only in the resolve pass (shaders/common/resolve.glsl + ops/*.glsl), so any
// method can drive any operation its payload supports.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/gl/gpu_scene.hpp"
#include "mfr/gl/program.hpp"
#include "mfr/gl/timer.hpp"
#include "mfr/methods/stats.hpp"

namespace mfr {

// A method parameter, described once: the CLI parses it and the viewer builds its widget from it.
struct ParamSpec {
  enum class Type { Int, Float, Bool, Choice, Text };  // Text: free text (a file path)
  std::string name;                                    // CLI: --param name=value
  std::string label;                                   // viewer label
  Type type = Type::Int;
  std::string defaultValue;
  double min = 0, max = 0;           // Int/Float range (inclusive)
  std::vector<std::string> choices;  // Choice
  std::string help;
  // A memory amount for the whole image (MiB): a frame of fewer pixels that should look like this
  // one (the viewer's reduced frames while navigating) gets the same share of it per pixel.
  bool perImage = false;
  // "pool=fixed": the parameter acts only while another has that value. Given with another value
  // it would be ignored without a word; the command lines refuse it (unusedMethodParam).
  std::string onlyWith{};
};

// A parameter's default for the operation a render runs ("auto" resolved). What only hybrid
// transparency reads is off by default under another operation, so that it costs no memory and
// bounds nothing there: fkb's tail (its 20 bytes a pixel went to the tail, not slots, under
// --op oit; a bug hunt) and vkb's and dkb's exact_tail. Renders, the viewer's parameter widgets and
// mfr info show the same.
[[nodiscard]] std::string defaultValueFor(const ParamSpec& spec, const std::string& operation);

// Values of a method's parameters, validated against its specs.
class Params {
 public:
  Params() = default;
  // Throws mfr::Error("--param <name>", reason) for an unknown name or a bad value.
  Params(const std::vector<ParamSpec>& specs, const std::map<std::string, std::string>& values,
         const std::string& method);
  [[nodiscard]] long long integer(const std::string& name) const;
  [[nodiscard]] double real(const std::string& name) const;
  [[nodiscard]] bool flag(const std::string& name) const;
  [[nodiscard]] const std::string& text(const std::string& name) const;

 private:
  std::map<std::string, std::string> values_;
};

struct MethodInfo {
  std::string name;   // registry name, e.g. "abuffer-ll"
  std::string title;  // e.g. "A-buffer, per-pixel linked lists"
  std::string paper;  // citation of the implemented paper
  bool exact = true;  // captures every fragment (given enough memory/passes)
  std::vector<ParamSpec> params;
  std::string preferredOperation = "oit";  // what --op auto runs ("hybrid" for the budget methods)
  // Its capture stores every fragment through mfrCurrentFragment() and leaves colours alone until
  // the resolve, so it can carry object ids instead (MFR_PAYLOAD_OBJECT): the operation "csg".
  bool objectPayload = false;
  // Its resolve hands each pixel's whole sorted list to the operation (resolve.glsl and the
  // k-buffer family's resolve), so it runs the list operations "zthickness" and "volume". False for
  // the peeling methods (they composite while they peel), WBOIT, MBOIT (no lists) and
  // kbuffer-zmerge (merged segments).
  bool sortedLists = true;
};

// What the resolve pass does with each pixel's sorted list.
struct Operation {
  std::string name;                              // "oit", "dump"
  std::string glslFile;                          // e.g. "ops/oit.glsl": defines OpState, opBegin, opFragment, opEnd
  std::function<void(const gl::Program&)> bind;  // uniforms and buffers of the operation
};

struct FrameContext {
  const gl::GpuScene& scene;
  gl::FrameUniforms frame;
  glm::vec3 background{1.0f};
  int width = 0;
  int height = 0;
  gl::PassTimer& timer;
  // Operation "zthickness": slab thickness (scene units) and window depth → eye depth
  // (Camera::depthToEye), for methods that merge slabs already while they capture.
  float zThickness = 0.0f;
  glm::vec4 depthToEye{0.0f};
};

class Method {
 public:
  virtual ~Method() = default;
  [[nodiscard]] virtual const MethodInfo& info() const = 0;
  // Image size and parameters; allocates size-dependent storage. Throws mfr::Error.
  virtual void configure(int width, int height, const Params& params) = 0;
  // Rasterises the scene into the method's per-pixel structure.
  virtual void capture(const FrameContext& ctx) = 0;
  // Runs op on every pixel's sorted fragments, writing into the bound draw framebuffer.
  virtual void resolve(const FrameContext& ctx, const Operation& op) = 0;
  // Stats of the last capture + resolve (pass times are filled in by the caller from ctx.timer).
  [[nodiscard]] virtual Stats stats() const = 0;
  // Per-pixel capacity k(p) of the last capture, in GL row order (bottom row first), width·height
  // entries; empty for methods without a per-pixel capacity (A-buffers, peeling, WBOIT, MBOIT).
  [[nodiscard]] virtual std::vector<std::uint32_t> capacityMap() const { return {}; }
};

// Builds (and caches per operation) the screen pass of a method that runs an operation:
// common/fullscreen.vert + methods/<folder>/<passFile> with the operation included (MFR_OP_FILE).
class ResolveProgramCache {
 public:
  const gl::Program& get(const std::string& methodFolder, const Operation& op, const gl::Defines& extra = {},
                         const std::string& passFile = "resolve.screen.frag");

 private:
  std::map<std::string, gl::Program> programs_;
};

}  // namespace mfr
