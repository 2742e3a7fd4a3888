#include "abuffer_linked_list.hpp"

#include <algorithm>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {
namespace {
constexpr std::uint64_t kNodeBytes = 12;  // packed RGBA8 + float depth + next index
}

const MethodInfo& ABufferLinkedList::info() const {
  static const MethodInfo i{
      "abuffer-ll",
      "A-buffer, per-pixel linked lists",
      "Yang, Hensley, Grün, Thibieroz: Real-Time Concurrent Linked List Construction on the GPU. CGF 29(4), EGSR 2010",
      true,
      {{"pool",
        "Pool sizing",
        ParamSpec::Type::Choice,
        "count",
        0,
        0,
        {"count", "previous", "fixed"},
        "count: exact count pass first; previous: last frame's count + 10 %; fixed: pool_mib"},
       {"pool_mib",
        "Fixed pool (MiB)",
        ParamSpec::Type::Float,
        "64",
        0,
        65536,
        {},
        "node pool size when pool=fixed",
        true,
        "pool=fixed"}},
      "oit",
      true};
  return i;
}

void ABufferLinkedList::configure(int width, int height, const Params& params) {
  sizing_ = params.text("pool");
  fixedPoolNodes_ = static_cast<std::uint64_t>(params.real("pool_mib") * 1024.0 * 1024.0) / kNodeBytes;
  if (sizing_ == "fixed")  // it was cut to what fits without a word
    requireStorageFits("--param pool_mib=" + params.text("pool_mib"),
                       "a pool of " + std::to_string(fixedPoolNodes_) + " nodes x 12 bytes", fixedPoolNodes_,
                       maxStorageElements(kNodeBytes), kNodeBytes, "");
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    heads_ = gl::createTexture2D(GL_R32UI, width, height);
  }
  if (!counter_) counter_ = gl::createBuffer(2 * sizeof(std::uint32_t));
  if (!store_.id()) {
    count_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/abuffer-ll/count.geom.frag"}});
    store_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/abuffer-ll/store.geom.frag"}});
  }
}

void ABufferLinkedList::ensurePool(std::uint64_t nodes) {
  // Only pool=previous's guess is ever cut here (its overflow is counted, as documented).
  nodes = std::clamp<std::uint64_t>(nodes, 1, maxStorageElements(kNodeBytes));
  if (nodes != poolNodes_) {
    pool_ = gl::createBuffer(nodes * kNodeBytes);
    poolNodes_ = nodes;
  }
}

void ABufferLinkedList::capture(const FrameContext& ctx) {
  stats_ = Stats{};
  GeometryPassState state;  // no depth test, no culling, colour writes off
  const std::uint32_t zero[2] = {0, 0};
  glNamedBufferSubData(counter_.id(), 0, sizeof zero, zero);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counter_.id());

  std::uint64_t want = 0;
  if (sizing_ == "count") {
    ctx.timer.begin("count");
    ctx.scene.draw(count_, ctx.frame);
    ctx.timer.end();
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    std::uint32_t counts[2] = {0, 0};
    glGetNamedBufferSubData(counter_.id(), 0, sizeof counts, counts);
    want = counts[0];
    // The exact pool: a frame whose fragments do not fit is refused, not drawn without some.
    requireStorageFits("--method abuffer-ll",
                       std::to_string(width_) + "x" + std::to_string(height_) + ": the frame's " +
                           std::to_string(want) + " fragments x 12 bytes",
                       want, maxStorageElements(kNodeBytes), kNodeBytes, "; a smaller --size needs less");
    glNamedBufferSubData(counter_.id(), 0, sizeof zero, zero);
    stats_.passes += 1;
  } else if (sizing_ == "previous") {
    // First frame: a guess of 8 fragments per pixel; afterwards last frame's demand + 10 %.
    want = previousCount_ > 0 ? previousCount_ + previousCount_ / 10 + 1024
                              : static_cast<std::uint64_t>(width_) * height_ * 8;
  } else {
    want = fixedPoolNodes_;
  }
  ensurePool(want);

  const GLuint nil = MFR_NIL;
  glClearTexImage(heads_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &nil);
  glBindImageTexture(MFR_IMAGE_HEADS, heads_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, pool_.id());
  store_.set("uPoolSize", static_cast<unsigned>(poolNodes_));
  ctx.timer.begin("store");
  ctx.scene.draw(store_, ctx.frame);
  ctx.timer.end();
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  stats_.passes += 1;

  std::uint32_t counts[2] = {0, 0};
  glGetNamedBufferSubData(counter_.id(), 0, sizeof counts, counts);
  previousCount_ = counts[0];
  stats_.fragmentsGenerated = counts[0];
  stats_.fragmentsStored = std::min<std::uint64_t>(counts[0], poolNodes_);
  stats_.fragmentsDropped = counts[1];
  stats_.overflow = counts[1] > 0;
  // The shared pool fills in arrival order: which pixels lost fragments is not known (a bug hunt
  // read overflow_pixels = 0 beside 50,486 dropped fragments as "no pixel lost any").
  if (stats_.overflow)
    stats_.notes.emplace_back("overflow pixels",
                              "not counted: the shared pool drops fragments in arrival order, whatever their pixel");
  const std::uint64_t headBytes = static_cast<std::uint64_t>(width_) * height_ * 4;
  stats_.bytesAllocated = headBytes + poolNodes_ * kNodeBytes + sizeof zero;
  stats_.bytesUsed = headBytes + stats_.fragmentsStored * kNodeBytes + sizeof zero;
  stats_.notes.emplace_back("pool sizing", sizing_);
  stats_.notes.emplace_back("pool nodes", std::to_string(poolNodes_));
}

void ABufferLinkedList::resolve(const FrameContext& ctx, const Operation& op) {
  const gl::Program& program = resolve_.get("abuffer-ll", op);
  glBindImageTexture(MFR_IMAGE_HEADS, heads_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, pool_.id());
  program.set("uMaxListLength", static_cast<unsigned>(std::min<std::uint64_t>(poolNodes_, MFR_MAX_LIST_WALK)));
  runResolvePass(ctx, program, op);
}

Stats ABufferLinkedList::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "atomics";
  return s;
}

}  // namespace mfr
