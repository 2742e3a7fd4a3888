#include "abuffer_sbuffer.hpp"

#include <algorithm>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {
namespace {
// Fragments one buffer may hold: the largest storage block, and 32-bit offsets.
std::uint64_t maxFragments() {
  return std::min<std::uint64_t>(maxStorageElements(8), 0xFFFFFFFFull);
}
}  // namespace

const MethodInfo& ABufferSBuffer::info() const {
  static const MethodInfo i{
      "abuffer-sbuffer",
      "A-buffer, S-buffer (variable-length contiguous per-pixel arrays)",
      "Vasilakis, Fudos: S-buffer: Sparsity-aware Multi-fragment Rendering. Eurographics 2012 Short Papers; "
      "Maule, Comba, Torchelsen, Bastos: Memory-Efficient Order-Independent Transparency with Dynamic Fragment "
      "Buffer. SIBGRAPI 2012",
      true,
      {{"pool",
        "Fragment buffer sizing",
        ParamSpec::Type::Choice,
        "count",
        0,
        0,
        {"count", "previous", "fixed"},
        "count: this frame's scanned total (one 4-byte read-back between the scan and the store pass); previous: "
        "last frame's total + 10 % (no read-back before storing; overflow is counted); fixed: pool_mib"},
       {"pool_mib",
        "Fixed fragment buffer (MiB)",
        ParamSpec::Type::Float,
        "64",
        0,
        65536,
        {},
        "fragment buffer size when pool=fixed",
        true,
        "pool=fixed"}},
      "oit",
      true};
  return i;
}

void ABufferSBuffer::configure(int width, int height, const Params& params) {
  sizing_ = params.text("pool");
  fixedCapacity_ = static_cast<std::uint64_t>(params.real("pool_mib") * 1024.0 * 1024.0) / kFragmentBytes;
  if (sizing_ == "fixed")  // it was cut to what fits without a word
    requireStorageFits("--param pool_mib=" + params.text("pool_mib"),
                       "a buffer of " + std::to_string(fixedCapacity_) + " fragments x 8 bytes", fixedCapacity_,
                       maxFragments(), kFragmentBytes, "");
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    const std::uint64_t entries = static_cast<std::uint64_t>(width) * height + 1;
    counts_ = gl::createBuffer(entries * 4);
    offsets_ = gl::createBuffer(entries * 4);
  }
  if (!counter_) counter_ = gl::createBuffer(kCounterBytes);
  if (!store_.id()) {
    count_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/abuffer-sbuffer/count.geom.frag"}});
    store_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/abuffer-sbuffer/store.geom.frag"}});
  }
}

void ABufferSBuffer::ensureCapacity(std::uint64_t fragments) {
  fragments = std::clamp<std::uint64_t>(fragments, 1, maxFragments());
  if (fragments != capacity_ || !fragments_) {
    fragments_ = gl::createBuffer(fragments * kFragmentBytes);
    capacity_ = fragments;
  }
}

void ABufferSBuffer::capture(const FrameContext& ctx) {
  stats_ = Stats{};
  const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * height_;
  const GLuint zero = 0;
  // The extra last entry stays 0, so the scan's entry width·height is the total: every pixel's
  // range ends at offsets[p + 1].
  glClearNamedBufferData(counts_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearNamedBufferData(counter_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

  {
    GeometryPassState state;  // no depth test, no culling, colour writes off
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, counts_.id());
    count_.set("uWidth", width_);
    ctx.timer.begin("count");
    ctx.scene.draw(count_, ctx.frame);
    ctx.timer.end();
  }
  stats_.passes += 1;

  ctx.timer.begin("scan");
  scan_.scan(counts_.id(), offsets_.id(), static_cast<std::uint32_t>(pixels + 1));
  ctx.timer.end();

  if (sizing_ == "count") {
    // The one CPU round trip: the total sizes the fragment buffer exactly; a frame whose fragments
    // do not fit is refused, not drawn without some.
    const std::uint64_t total = scan_.readTotal();
    requireStorageFits("--method abuffer-sbuffer",
                       std::to_string(width_) + "x" + std::to_string(height_) + ": the frame's " +
                           std::to_string(total) + " fragments x 8 bytes",
                       total, maxFragments(), kFragmentBytes, "; a smaller --size needs less");
    ensureCapacity(total);
  } else if (sizing_ == "previous") {
    // First frame: a guess of 8 fragments per pixel; afterwards last frame's total + 10 %.
    ensureCapacity(previousTotal_ > 0 ? previousTotal_ + previousTotal_ / 10 + 1024 : pixels * 8);
  } else {
    ensureCapacity(fixedCapacity_);
  }

  // The counts become the store pass's per-pixel cursors.
  glClearNamedBufferData(counts_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  {
    GeometryPassState state;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, counts_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, offsets_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, fragments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counter_.id());
    store_.set("uWidth", width_);
    store_.set("uCapacity", static_cast<unsigned>(capacity_));
    ctx.timer.begin("store");
    ctx.scene.draw(store_, ctx.frame);
    ctx.timer.end();
  }
  stats_.passes += 1;
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);

  const std::uint64_t total = scan_.readTotal();
  std::uint32_t counter[2] = {0, 0};
  glGetNamedBufferSubData(counter_.id(), 0, sizeof counter, counter);
  previousTotal_ = total;
  stats_.fragmentsGenerated = total;
  stats_.fragmentsDropped = counter[0];
  stats_.fragmentsStored = total >= counter[0] ? total - counter[0] : 0;
  stats_.overflowPixels = counter[1];
  stats_.overflow = counter[0] > 0;
  const std::uint64_t perPixelBytes = 2 * (pixels + 1) * 4;  // counts/cursors + offsets
  const std::uint64_t fixedBytes = scan_.bytesAllocated() + kCounterBytes;
  stats_.bytesAllocated = perPixelBytes + capacity_ * kFragmentBytes + fixedBytes;
  stats_.bytesUsed = perPixelBytes + stats_.fragmentsStored * kFragmentBytes + fixedBytes;
  stats_.notes.emplace_back("pool sizing", sizing_);
  stats_.notes.emplace_back("capacity (fragments)", std::to_string(capacity_));
  stats_.notes.emplace_back("scan scratch (bytes)", std::to_string(scan_.bytesAllocated()));
}

void ABufferSBuffer::resolve(const FrameContext& ctx, const Operation& op) {
  const gl::Program& program = resolve_.get("abuffer-sbuffer", op);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, counts_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, offsets_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, fragments_.id());
  program.set("uWidth", width_);
  program.set("uCapacity", static_cast<unsigned>(capacity_));
  program.set("uMaxListLength", static_cast<unsigned>(std::min<std::uint64_t>(capacity_, MFR_MAX_LIST_WALK)));
  runResolvePass(ctx, program, op);
}

Stats ABufferSBuffer::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "atomics";
  return s;
}

}  // namespace mfr
