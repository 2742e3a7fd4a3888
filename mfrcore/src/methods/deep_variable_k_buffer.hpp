#pragma once
// dkb: the deep variable k-buffer (Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent
// transparency", The Visual Computer 2022): two feature passes (n(p), nearest/farthest depth and
// colour sums; the nearest fragment's colour), the image sums, then a compute pass that builds the
// 12 features per pixel and runs the MLP (12→128→64→1) from a weights file to predict k(p); the
// prediction is the importance the shared allocation rule distributes F(M) by; then the same
// store and hybrid resolve as vkb. Shaders: shaders/methods/dkb.
#include "mfr/budget/neural_importance.hpp"
#include "variable_k_buffer.hpp"

namespace mfr {

class DeepVariableKBuffer final : public VariableKBuffer {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  [[nodiscard]] const NeuralImportanceModel& model() const { return model_; }

 protected:
  [[nodiscard]] std::string folder() const override { return "dkb"; }
  void configureMember(const Params& params) override;
  [[nodiscard]] std::uint64_t memberFixedBytes() const override;
  void clearFeatures() override;
  std::uint32_t drawFeatures(const FrameContext& ctx) override;
  [[nodiscard]] bool needsDepthRange() const override { return true; }
  [[nodiscard]] std::uint32_t farthestDepthRegion() const override { return 1; }
  void computeImportance(const FrameContext& ctx) override;
  [[nodiscard]] std::string describeImportance() const override;

 private:
  std::string weightsPath_;  // of the loaded model ("" = built-in; none loaded while !weights_)
  NeuralImportanceModel model_;
  gl::Buffer weights_;
  gl::Program count_, nearest_, mlp_;
};

}  // namespace mfr
