#pragma once
// Dual depth peeling (Bavoil & Myers, "Order Independent Transparency with Dual Depth Peeling",
// NVIDIA 2008). Shaders: shaders/methods/peel-dual. Each geometry pass peels the nearest and the
// farthest remaining layer (MAX blending of (−z, z)); fronts are composited front to back, backs
// back to front, and a final pass joins them. An occlusion query per pass stops the peeling.
#include <map>

#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

class DualDepthPeeling final : public Method {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  // Peeling composites while it peels, so capture only resets the stats: every pass runs in
  // resolve(), with the operation known.
  void capture(const FrameContext& ctx) override;
  // Supports "oit" (composited image) and "dump" (front layer i at position i, back layer i at
  // position P−1−i); throws mfr::Error for any other operation.
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

  // Bytes per pixel of the textures it owns: two RG32F depth ranges (2 × 8), RGBA32F peeled
  // layer colours (16), RGBA32F front and back accumulations (2 × 16).
  static constexpr std::uint64_t kBytesPerPixel = 2 * 8 + 16 + 2 * 16;

 private:
  int width_ = 0, height_ = 0;
  int maxPasses_ = 32;
  gl::Texture range_[2];
  gl::Texture layers_;
  gl::Texture front_, back_;
  gl::Framebuffer initFbo_;      // range_[0] + front_ (the per-pixel count in dump frames)
  gl::Framebuffer peelFbo_[2];   // range_[i] + layers_
  gl::Framebuffer accumFbo_;     // front_ + back_
  gl::Framebuffer noAttachFbo_;  // side-effect and query-only passes
  gl::VertexArray emptyVao_;
  gl::Program peel_, blend_, remaining_, final_;
  ResolveProgramCache dumpPrograms_;  // the dump pass, per operation file
  Stats stats_;
};

}  // namespace mfr
