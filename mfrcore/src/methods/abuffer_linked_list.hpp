#pragma once
// A-buffer with per-pixel linked lists (Yang et al., EGSR 2010). Shaders: shaders/methods/abuffer-ll.
#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

class ABufferLinkedList final : public Method {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

 private:
  void ensurePool(std::uint64_t nodes);

  int width_ = 0, height_ = 0;
  std::string sizing_ = "count";
  std::uint64_t fixedPoolNodes_ = 0;
  std::uint64_t poolNodes_ = 0;
  std::uint64_t previousCount_ = 0;
  gl::Texture heads_;
  gl::Buffer pool_;
  gl::Buffer counter_;
  gl::Program count_, store_;
  ResolveProgramCache resolve_;
  Stats stats_;
};

}  // namespace mfr
