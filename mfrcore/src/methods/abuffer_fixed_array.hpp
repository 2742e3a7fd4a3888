#pragma once
// A-buffer with fixed-size per-pixel arrays (Liu et al., FreePipe, I3D 2010; Crassin 2010).
// Shaders: shaders/methods/abuffer-array.
#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

class ABufferFixedArray final : public Method {
 public:
  // Bytes of the statistics buffer (generated, dropped, overflow pixels, max count).
  static constexpr std::uint64_t kStatsBytes = 16;
  static constexpr std::uint64_t kFragmentBytes = 8;

  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

 private:
  void ensureSlots(std::uint32_t slots);
  struct Reduced {
    std::uint32_t generated = 0, dropped = 0, overflowPixels = 0, maxCount = 0;
  };
  Reduced reduceCounts(const FrameContext& ctx, const char* pass);

  int width_ = 0, height_ = 0;
  std::uint32_t requestedSlots_ = 32;  // 0: size from a count pass
  std::uint32_t slots_ = 0;            // allocated capacity per pixel
  gl::Texture counts_;
  gl::Buffer fragments_;
  gl::Buffer statsBuffer_;
  gl::Program count_, store_, reduce_;
  ResolveProgramCache resolve_;
  Stats stats_;
};

}  // namespace mfr
