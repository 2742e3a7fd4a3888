#pragma once
// vkb: the variable k-buffer with importance maps (Vasilakis, Vardis, Papaioannou, Moustakas,
// "Variable k-buffer using Importance Maps", EG 2017 Short Papers) under a memory budget, with the
// tail of hybrid transparency. Importance from periphery, depth complexity, the nearest fragment's
// Fresnel term and noise (shaders/budget/importance.h); allocation, store and resolve shared with
// dkb (variable_k_buffer.hpp). Shaders: shaders/methods/vkb.
#include "variable_k_buffer.hpp"

namespace mfr {

class VariableKBufferImportance final : public VariableKBuffer {
 public:
  [[nodiscard]] const MethodInfo& info() const override;

 protected:
  [[nodiscard]] std::string folder() const override { return "vkb"; }
  void configureMember(const Params& params) override;
  void clearFeatures() override;
  std::uint32_t drawFeatures(const FrameContext& ctx) override;
  [[nodiscard]] std::uint32_t farthestDepthRegion() const override { return 2; }
  void computeImportance(const FrameContext& ctx) override;
  [[nodiscard]] std::string describeImportance() const override;

 private:
  glm::vec2 pointOfInterest_{0.5f};
  float falloff_ = 0.35f, depthLimit_ = 32.0f, depthAlpha_ = 1.0f, noise_ = 0.0f;
  glm::vec3 weights_{1.0f};
  gl::Program count_, nearest_, importance_;
};

}  // namespace mfr
