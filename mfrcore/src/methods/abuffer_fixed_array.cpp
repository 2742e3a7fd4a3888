#include "abuffer_fixed_array.hpp"

#include <algorithm>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "method_util.hpp"

namespace mfr {
namespace {
constexpr std::uint32_t kMaxSlots = 1024;

// Fragments one array may hold: the largest storage block, and 32-bit slot addresses.
std::uint64_t maxFragments() {
  return std::min<std::uint64_t>(maxStorageElements(8), 0xFFFFFFFFull);
}

}  // namespace

const MethodInfo& ABufferFixedArray::info() const {
  static const MethodInfo i{
      "abuffer-array",
      "A-buffer, fixed-size per-pixel arrays",
      "Liu, Huang, Liu, Wu: FreePipe: a Programmable Parallel Rendering Architecture for Efficient Multi-Fragment "
      "Effects. I3D 2010; Crassin: Fast and Accurate Single-Pass A-Buffer using OpenGL 4.0+ (2010)",
      true,
      {{"slots",
        "Fragments per pixel",
        ParamSpec::Type::Int,
        "32",
        0,
        kMaxSlots,
        {},
        "array capacity per pixel; fragments beyond it are dropped and counted. 0: size from a count pass to the "
        "largest per-pixel count"}},
      "oit",
      true};
  return i;
}

void ABufferFixedArray::configure(int width, int height, const Params& params) {
  requestedSlots_ = static_cast<std::uint32_t>(params.integer("slots"));
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    counts_ = gl::createTexture2D(GL_R32UI, width, height);
    fragments_.reset();
    slots_ = 0;
  }
  if (!statsBuffer_) statsBuffer_ = gl::createBuffer(kStatsBytes);
  if (!store_.id()) {
    count_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/abuffer-array/count.geom.frag"}});
    store_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/abuffer-array/store.geom.frag"}});
    reduce_ = gl::Program({{GL_COMPUTE_SHADER, "methods/abuffer-array/stats.comp"}});
  }
  if (requestedSlots_ > 0) {
    const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * height_;
    const std::uint64_t limit = maxFragments();
    if (pixels * requestedSlots_ > limit) {
      throw Error(
          "--param slots=" + std::to_string(requestedSlots_),
          std::to_string(width_) + "x" + std::to_string(height_) + " pixels x " + std::to_string(requestedSlots_) +
              " slots x 8 bytes = " + formatMemory(pixels * requestedSlots_ * kFragmentBytes) +
              " exceeds the largest shader storage block of this GL context (" + formatMemory(limit * kFragmentBytes) +
              "); at most " + std::to_string(limit / pixels) + " slots fit");
    }
    ensureSlots(requestedSlots_);
  }
}

void ABufferFixedArray::ensureSlots(std::uint32_t slots) {
  if (slots == slots_ && fragments_) return;
  const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * height_;
  fragments_ = gl::createBuffer(pixels * slots * kFragmentBytes);
  slots_ = slots;
}

ABufferFixedArray::Reduced ABufferFixedArray::reduceCounts(const FrameContext& ctx, const char* pass) {
  const std::uint32_t zero[4] = {0, 0, 0, 0};
  glNamedBufferSubData(statsBuffer_.id(), 0, sizeof zero, zero);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindImageTexture(MFR_IMAGE_COUNTS, counts_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, statsBuffer_.id());
  reduce_.use();
  reduce_.set("uSlots", slots_);
  reduce_.set("uSize", glm::ivec2(width_, height_));
  ctx.timer.begin(pass);
  glDispatchCompute(static_cast<GLuint>((width_ + 15) / 16), static_cast<GLuint>((height_ + 15) / 16), 1);
  ctx.timer.end();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  Reduced r;
  std::uint32_t values[4] = {0, 0, 0, 0};
  glGetNamedBufferSubData(statsBuffer_.id(), 0, sizeof values, values);
  r.generated = values[0];
  r.dropped = values[1];
  r.overflowPixels = values[2];
  r.maxCount = values[3];
  return r;
}

void ABufferFixedArray::capture(const FrameContext& ctx) {
  stats_ = Stats{};
  const GLuint zero = 0;
  const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * height_;

  if (requestedSlots_ == 0) {
    // Automatic sizing: count pass, reduce to the largest per-pixel count (one 16-byte read-back),
    // allocate that many slots (clamped to 1..1024; refused beyond the largest storage block).
    glClearTexImage(counts_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    {
      GeometryPassState state;
      glBindImageTexture(MFR_IMAGE_COUNTS, counts_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
      ctx.timer.begin("count");
      ctx.scene.draw(count_, ctx.frame);
      ctx.timer.end();
    }
    stats_.passes += 1;
    const Reduced counted = reduceCounts(ctx, "count max");  // slots_ is stale here: only maxCount is used
    const auto want =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(std::max<std::uint32_t>(counted.maxCount, 1), kMaxSlots));
    // The deepest pixel's slots for every pixel, or a refusal: cutting them to what fits dropped
    // fragments of an "exact" method without a word.
    requireStorageFits(
        "--method abuffer-array",
        std::to_string(width_) + "x" + std::to_string(height_) + " pixels x " + std::to_string(want) +
            (counted.maxCount > kMaxSlots ? " slots (the most there are; the deepest pixel has " +
                                                std::to_string(counted.maxCount) + " fragments) x 8 bytes"
                                          : " slots (the deepest pixel's fragments) x 8 bytes"),
        pixels * want, maxFragments(), kFragmentBytes, "; a smaller --size needs less");
    ensureSlots(want);
  }

  glClearTexImage(counts_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  {
    GeometryPassState state;  // no depth test, no culling, colour writes off
    glBindImageTexture(MFR_IMAGE_COUNTS, counts_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, fragments_.id());
    store_.set("uSlots", slots_);
    store_.set("uPixels", static_cast<unsigned>(pixels));
    store_.set("uWidth", width_);
    ctx.timer.begin("store");
    ctx.scene.draw(store_, ctx.frame);
    ctx.timer.end();
  }
  stats_.passes += 1;

  // The counters hold the true arrivals: reduce them to generated / dropped / overflowing pixels.
  const Reduced r = reduceCounts(ctx, "stats");
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  stats_.fragmentsGenerated = r.generated;
  stats_.fragmentsDropped = r.dropped;
  stats_.fragmentsStored = r.generated - r.dropped;
  stats_.overflowPixels = r.overflowPixels;
  stats_.overflow = r.dropped > 0;
  stats_.kMin = stats_.kMax = slots_;
  const std::uint64_t counterBytes = pixels * 4;
  stats_.bytesAllocated = counterBytes + pixels * slots_ * kFragmentBytes + kStatsBytes;
  stats_.bytesUsed = counterBytes + stats_.fragmentsStored * kFragmentBytes + kStatsBytes;
  stats_.notes.emplace_back("slots", std::to_string(slots_) + (requestedSlots_ == 0 ? " (from count pass)" : ""));
  stats_.notes.emplace_back("largest per-pixel arrivals", std::to_string(r.maxCount));
}

void ABufferFixedArray::resolve(const FrameContext& ctx, const Operation& op) {
  const gl::Program& program = resolve_.get("abuffer-array", op);
  glBindImageTexture(MFR_IMAGE_COUNTS, counts_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, fragments_.id());
  program.set("uSlots", slots_);
  program.set("uPixels", static_cast<unsigned>(static_cast<std::uint64_t>(width_) * height_));
  program.set("uWidth", width_);
  program.set("uMaxListLength", slots_);
  runResolvePass(ctx, program, op);
}

Stats ABufferFixedArray::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "atomics";
  return s;
}

}  // namespace mfr
