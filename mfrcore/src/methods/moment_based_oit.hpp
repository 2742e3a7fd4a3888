#pragma once
// Moment-based order-independent transparency (Münstermann, Krumpen, Klein, Peters, Proc. ACM CGIT
// 1(1), 2018): an additive pass accumulates power moments of the absorbance −ln(1 − α) over
// warped depth, a second additive pass composites every fragment with the transmittance
// reconstructed from them, and a screen pass normalises with the exact total transmittance.
// Approximate: it keeps no fragment lists, so only the "oit" operation is supported.
// Shaders: shaders/methods/mboit.
#include <map>
#include <string>

#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

class MomentBasedOit final : public Method {
 public:
  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  void capture(const FrameContext& ctx) override;
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

  // Bytes per pixel: R32F b_0 + RGBA32F b_1..4 (+ RG32F b_5,6) + RGBA16F colour accumulation.
  static std::uint64_t bytesPerPixel(int moments);
  // The paper's moment bias for single-precision power moments (5e-7 for 4, 5e-6 for 6).
  static double paperBias(int moments);

 private:
  struct Programs {
    gl::Program moments, accumulate;
  };
  Programs& programs();

  int width_ = 0, height_ = 0;
  int moments_ = 0;  // 4 or 6
  double bias_ = 0.0, overestimation_ = 0.25;
  std::string warp_ = "log";
  gl::Texture b0_, b1234_, b56_, accum_;
  gl::Framebuffer momentsFbo_, accumFbo_;
  gl::Query samples_;
  std::map<int, Programs> programs_;  // per moment count
  gl::Program composite_;
  Stats stats_;
};

}  // namespace mfr
