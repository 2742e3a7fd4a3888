#pragma once
// Classic k-buffer (Bavoil, Callahan, Lefohn, Comba, Silva, "Multi-fragment effects on the GPU
// using the k-buffer", I3D 2007), done correctly: insertion into the pixel's depth-sorted array of
// k inside a per-pixel critical section. Shaders: shaders/methods/kbuffer.
#include "kbuffer_common.hpp"

namespace mfr {

class KBufferSorted final : public KBufferFamily {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
};

}  // namespace mfr
