#pragma once
// Weighted blended order-independent transparency (McGuire & Bavoil, JCGT 2(2), 2013): one
// additive geometry pass into a weighted colour sum and a revealage product, then a composite.
// Approximate: it keeps no fragment lists, so only the "oit" operation is supported.
// Shaders: shaders/methods/wboit. DepthMapping (below) is shared with moment_based_oit.cpp.
#include <map>
#include <string>

#include <glm/glm.hpp>

#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

// View depth from window depth, recovered from the view-projection matrix alone (FrameContext
// carries no near/far). V is rigid (a look-at frame), so P·V keeps P's depth row up to V's
// rotation: row 3 of P·V is −(row 2 of V) for a perspective P and (0,0,0,1) for an orthographic
// one, and row 2 is a·(row 2 of V) + b·e4.
//   perspective:  |z_eye| = b / (ndc + a), near = b / (a − 1), far = b / (a + 1)
//   orthographic: row 2's translation mixes b with the eye position, so |z_eye| is unknown; the
//                 distance behind the near plane, (ndc + 1) / a, is used instead (near = 0).
// GLSL side: shaders/methods/wboit/view_depth.glsl (uniforms uPerspective, uDepthMap).
struct DepthMapping {
  bool perspective = true;
  float a = 1.0f, b = 1.0f;
  float nearDepth = 0.0f, farDepth = 1.0f;  // viewDepth at ndc = −1 and +1
  [[nodiscard]] float viewDepth(float ndc) const { return perspective ? b / (ndc + a) : (ndc + 1.0f) / a; }
  void bind(const gl::Program& program) const;
};
DepthMapping depthMapping(const glm::mat4& viewProj);

class WeightedBlendedOit final : public Method {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

  // Bytes per pixel of the two render targets: RGBA16F accumulation + R8 or R16F revealage.
  static std::uint64_t bytesPerPixel(const std::string& revealageFormat);

 private:
  const gl::Program& accumulateProgram();

  int width_ = 0, height_ = 0;
  std::string weight_ = "eq7";
  std::string revealageFormat_;
  gl::Texture accum_, revealage_;
  gl::Framebuffer fbo_;
  gl::Query samples_;
  std::map<std::string, gl::Program> accumulate_;  // per weight function
  gl::Program composite_;
  Stats stats_;
};

}  // namespace mfr
