#pragma once
// What the k-buffer family shares (classic k-buffer, Bavoil et al. I3D 2007; k+-buffer max-array,
// max-heap, s-buffer and dynamic-k variants, Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015):
// the per-pixel slots of the 8-byte payload, the per-pixel critical section (spin lock or
// fragment shader interlock), the statistics counters, the tail accumulation hook, and the resolve
// pass. Shaders: shaders/common/kbuffer_*.glsl, shaders/methods/<name>/.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

// Per-pixel sums over the fragments that did NOT end among the pixel's k nearest (the "tail" of
// hybrid transparency): exact integer sums of the 8-bit stored values.
struct KBufferTail {
  std::uint32_t colorAlpha[3] = {0, 0, 0};  // Σ c·α per channel, units of 1/255²
  std::uint32_t alpha = 0;                  // Σ α, units of 1/255
  std::uint32_t count = 0;                  // fragments
};

// The per-pixel critical section a store pass runs under.
struct KBufferSync {
  std::string name;     // "spinlock" or "interlock" (Stats::sync)
  gl::Defines defines;  // for the store pass
};
// choice "spinlock" or "interlock"; throws Error("--param sync=interlock", "not supported by this
// OpenGL driver") when the context has no fragment shader interlock/ordering extension.
KBufferSync kbufferSync(const std::string& choice);

// Parameters every member understands: k, sync, spin_limit, tail; plus culling and/or revised.
std::vector<ParamSpec> kbufferParams(bool culling, bool revised, const std::string& kDefault = "8");

class KBufferFamily : public Method {
 public:
  static constexpr std::uint64_t kEntryBytes = 8;     // RGBA8 + float depth
  static constexpr std::uint64_t kCounterBytes = 32;  // statistics counters (8 uints)
  static constexpr std::uint64_t kTailBytesPerPixel = 20;

  void resolve(const FrameContext& ctx, const Operation& op) override;
  [[nodiscard]] Stats stats() const override;
  // Uniform k; variable-capacity members override it.
  [[nodiscard]] std::vector<std::uint32_t> capacityMap() const override;

  // Tail hook: with --param tail=true the store pass accumulates the fragments that leave (or
  // never enter) the k nearest into a per-pixel SSBO (5 uints, see KBufferTail), bound at
  // MFR_SSBO_TAIL during resolve so an operation can read it.
  [[nodiscard]] bool tailEnabled() const { return tail_; }
  [[nodiscard]] const gl::Buffer& tailBuffer() const { return tailBuffer_; }
  // Reads the tail back, image rows top-down (like the oracle). Empty when tail is off.
  [[nodiscard]] std::vector<KBufferTail> readTail() const;

 protected:
  // Common part of configure(): image size, sync, spin limit, tail; the store program from
  // methods/<storeFolder>/store.geom.frag with the given extra defines (culling, revised, …); the
  // resolve pass from methods/<resolveFolder>/resolve.screen.frag (with resolveDefines_).
  void configureCommon(int width, int height, const Params& params, const std::string& storeFolder,
                       const std::string& resolveFolder, const gl::Defines& storeDefines);
  // (Re)allocates the slot buffer for `slots` entries (all pixels together) and the per-pixel
  // auxiliary SSBO (MFR_SSBO_AUX, 0 for none). Throws Error("--param k", …) when too large.
  void allocateSlots(std::uint64_t slots, std::uint64_t auxBytes);
  // Clears slots (+inf), locks, aux, counters, tail; binds them for a store pass.
  void beginStore();
  // Draws the store pass (GeometryPassState: no depth test, colour writes off), timed as `pass`.
  void drawStore(const FrameContext& ctx, const char* pass = "store");
  // Reads the counters into stats_ (generated, stored, not kept, lock failures) and the memory
  // accounting; extraBytes: buffers a subclass owns besides slots/locks/aux/counters/tail.
  void finishStore(std::uint64_t extraBytes = 0);
  // Uniforms every k-buffer pass reads.
  void setCommonUniforms(const gl::Program& program) const;
  [[nodiscard]] std::uint64_t pixels() const { return static_cast<std::uint64_t>(width_) * height_; }

  // Set by members that keep the spin-lock words and the tail sums in their own per-pixel buffer
  // (the variable-k buffers' arena): configureCommon then allocates neither, the store pass takes
  // its locks from MFR_SSBO_LOCKS (MFR_KB_LOCKS_IN_BUFFER), and the member clears and binds them.
  bool externalPixelState_ = false;
  int width_ = 0, height_ = 0;
  std::uint32_t k_ = 1;
  std::uint32_t spinLimit_ = 1024;
  bool tail_ = false;
  KBufferSync sync_;
  std::string folder_;
  gl::Defines resolveDefines_;
  std::uint64_t slots_ = 0;
  std::uint64_t auxBytes_ = 0;
  gl::Buffer entries_, aux_, counters_, tailBuffer_;
  gl::Texture locks_;
  const gl::Program* store_ = nullptr;
  std::map<std::string, gl::Program> storePrograms_;
  ResolveProgramCache resolve_;
  Stats stats_;
};

}  // namespace mfr
