#pragma once
// k-buffer with z-thickness fragment merging (Kim & Kye, "Z-Thickness Blending: Effective Fragment
// Merging for Multi-Fragment Rendering", CGF 40(7) 2021): k segments per pixel; once they are full,
// the two segments that overlap most (else lie closest) are merged instead of a fragment being
// dropped. It drives the operation "zthickness" only. Shaders: shaders/methods/kbuffer-zmerge.
#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

class KBufferZThicknessMerge final : public Method {
 public:
  static constexpr std::uint64_t kSegmentBytes = 12;  // front, (length, optical depth) halves, RGBA8
  static constexpr std::uint64_t kCounterBytes = 32;

  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;
  [[nodiscard]] std::vector<std::uint32_t> capacityMap() const override;

 private:
  int width_ = 0, height_ = 0;
  std::uint32_t k_ = 0, spinLimit_ = 1024;
  gl::Buffer segments_, counters_;
  gl::Texture locks_;
  gl::Program store_, resolve_;
  Stats stats_;
};

}  // namespace mfr
