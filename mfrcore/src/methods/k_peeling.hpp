#pragma once
// k-peeling: the multi-pass k-buffer (Bavoil, Callahan, Lefohn, Comba, Silva, "Multi-fragment
// effects on the GPU using the k-buffer", I3D 2007): ceil(max n(p) / k) iterations, each a k-buffer
// pass (k+-buffer max-array in a per-pixel critical section) keeping the k nearest fragments
// strictly behind what the previous iterations composited, with front-to-back compositing between
// iterations. Exact (equals an A-buffer) for every k, in O(k) memory per pixel.
// Shaders: shaders/methods/kpeel.
#include <map>
#include <string>

#include "kbuffer_common.hpp"

namespace mfr {

class KPeeling final : public Method {
 public:
  static constexpr std::uint64_t kEntryBytes = 16;       // colour, depth, object id, primitive id
  static constexpr std::uint64_t kPixelStateBytes = 32;  // threshold key + count, OIT state
  static constexpr std::uint64_t kCountBytes = 4;        // count pass, then spin-lock semaphore
  static constexpr std::uint64_t kCounterBytes = 32;

  [[nodiscard]] const MethodInfo& info() const override;
  void configure(int width, int height, const Params& params) override;
  // The count pass (n(p), max n(p)); the iterations run in resolve, where the operation is known.
  void capture(const FrameContext& ctx) override;
  // Runs the iterations with op: "oit" composites front to back across iterations; stateless
  // per-fragment operations ("dump") see every fragment once, in order. Others: Error.
  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;

 private:
  const gl::Program& peelProgram(const Operation& op, bool carry);

  int width_ = 0, height_ = 0;
  std::uint32_t k_ = 8, spinLimit_ = 1024, maxIterations_ = 1024;
  std::uint32_t entriesK_ = 0;  // k the slot buffer was allocated for
  KBufferSync sync_;
  std::uint32_t maxCount_ = 0;
  gl::Buffer entries_, pixelState_, counters_;
  gl::Texture counts_;
  gl::Program count_;
  const gl::Program* store_ = nullptr;
  std::map<std::string, gl::Program> programs_;
  ResolveProgramCache final_;
  Stats stats_;
};

}  // namespace mfr
