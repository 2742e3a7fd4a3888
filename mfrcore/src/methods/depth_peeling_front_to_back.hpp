#pragma once
// Front-to-back depth peeling (Everitt, "Interactive Order-Independent Transparency", NVIDIA
// 2001). Shaders: shaders/methods/peel-f2b. One geometry pass per layer, composited front to
// back as it is peeled; an occlusion query per pass stops at the first empty layer.
#include <map>

#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

class DepthPeelingFrontToBack final : public Method {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  // Peeling composites while it peels, so capture only resets the stats: every pass runs in
  // resolve(), with the operation known.
  void capture(const FrameContext& ctx) override;
  // Supports "oit" (composited image) and "dump" (each layer written at its sorted position);
  // throws mfr::Error for any other operation.
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

  // Bytes per pixel of the textures it owns: depth attachment (4), two layer payloads (2 × 8),
  // RGBA32F accumulation (16).
  static constexpr std::uint64_t kBytesPerPixel = 4 + 2 * 8 + 16;

 private:
  int width_ = 0, height_ = 0;
  int maxPasses_ = 64;
  gl::Texture depth_;
  gl::Texture layers_[2];
  gl::Texture accum_;
  gl::Framebuffer peelFbo_[2];
  gl::Framebuffer accumFbo_;
  gl::VertexArray emptyVao_;  // full-screen passes draw a generated triangle
  gl::Program peel_, blend_, final_;
  ResolveProgramCache dumpPrograms_;  // the dump pass, per operation file
  Stats stats_;
};

}  // namespace mfr
