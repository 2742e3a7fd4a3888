#include "kbuffer_zmerge.hpp"

#include <string>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {

const MethodInfo& KBufferZThicknessMerge::info() const {
  static const MethodInfo i{
      "kbuffer-zmerge",
      "k-buffer with z-thickness fragment merging",
      "Kim, Kye: Z-Thickness Blending: Effective Fragment Merging for Multi-Fragment Rendering. Computer Graphics "
      "Forum 40(7) 2021; per-pixel critical section of Vasilakis, Fudos: k+-buffer: Fragment Synchronized k-buffer. "
      "I3D 2014",
      false,
      {{"k",
        "Segments per pixel (k)",
        ParamSpec::Type::Int,
        "4",
        1,
        MFR_ZMERGE_MAX_K,
        {},
        "capacity per pixel; beyond it two segments are merged, the pair that overlaps most or, when none do, the "
        "two farthest (nothing is dropped)"},
       {"spin_limit",
        "Spin-lock attempts",
        ParamSpec::Type::Int,
        "1024",
        1,
        4096,
        {},
        "lock attempts per fragment before it is dropped (counted in lockFailures)"}},
      "zthickness",
      false,
      false};
  return i;
}

void KBufferZThicknessMerge::configure(int width, int height, const Params& params) {
  const auto k = static_cast<std::uint32_t>(params.integer("k"));
  spinLimit_ = static_cast<std::uint32_t>(params.integer("spin_limit"));
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * height;
  if (pixels * k > maxStorageElements(kSegmentBytes))
    throw Error("--param k=" + std::to_string(k), std::to_string(width) + "x" + std::to_string(height) +
                                                      " pixels x k segments x 12 bytes exceed the largest shader "
                                                      "storage block of this GL context");
  if (width != width_ || height != height_ || k != k_ || !segments_) {
    width_ = width;
    height_ = height;
    k_ = k;
    segments_ = gl::createBuffer(pixels * k * kSegmentBytes);
    locks_ = gl::createTexture2D(GL_R32UI, width, height);
  }
  if (!counters_) counters_ = gl::createBuffer(kCounterBytes);
  if (!store_.id()) {
    store_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/kbuffer-zmerge/store.geom.frag"}});
    resolve_ = gl::Program({{GL_VERTEX_SHADER, "common/fullscreen.vert"},
                            {GL_FRAGMENT_SHADER, "methods/kbuffer-zmerge/resolve.screen.frag"}});
  }
}

void KBufferZThicknessMerge::capture(const FrameContext& ctx) {
  if (!(ctx.zThickness > 0.0f)) throw Error("--thickness", "kbuffer-zmerge needs a positive z-thickness");
  stats_ = Stats{};
  const GLuint zero = 0;
  const GLuint empty = 0x7F800000u;  // every word +inf bits: front = +inf marks an empty slot
  glClearNamedBufferData(segments_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &empty);
  glClearNamedBufferData(counters_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearTexImage(locks_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  {
    GeometryPassState state;  // no depth test, no culling, colour writes off
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counters_.id());
    glBindImageTexture(MFR_IMAGE_LOCKS, locks_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    store_.set("uZmWidth", width_);
    store_.set("uZmPixels", static_cast<unsigned>(static_cast<std::uint64_t>(width_) * height_));
    store_.set("uZmK", k_);
    store_.set("uSpinLimit", spinLimit_);
    store_.set("uZThickness", ctx.zThickness);
    store_.set("uZmThickness", ctx.zThickness);
    store_.set("uDepthToEye", ctx.depthToEye);
    ctx.timer.begin("store");
    ctx.scene.draw(store_, ctx.frame);
    ctx.timer.end();
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  }
  std::uint32_t c[4] = {0, 0, 0, 0};
  glGetNamedBufferSubData(counters_.id(), 0, sizeof c, c);
  const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * height_;
  stats_.passes = 1;
  stats_.fragmentsGenerated = c[0];
  stats_.lockFailures = c[2];
  stats_.fragmentsDropped = c[2];  // a merge drops nothing; only a fragment that never got the lock is lost
  stats_.fragmentsStored = c[0] - c[2] - c[3];
  stats_.overflow = c[1] > 0;
  stats_.kMin = stats_.kMax = k_;
  stats_.bytesAllocated = pixels * k_ * kSegmentBytes + pixels * 4 + kCounterBytes;
  stats_.bytesUsed = stats_.bytesAllocated;
  stats_.notes.emplace_back("merges", std::to_string(c[1]));
  stats_.notes.emplace_back("transparent fragments (alpha 0, not stored)", std::to_string(c[3]));
}

void KBufferZThicknessMerge::resolve(const FrameContext& ctx, const Operation& op) {
  if (op.name != "zthickness")
    throw Error("--op " + op.name,
                "kbuffer-zmerge keeps merged z-thickness segments, not fragments: it supports the operation zthickness "
                "only");
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, segments_.id());
  resolve_.set("uZmWidth", width_);
  resolve_.set("uZmPixels", static_cast<unsigned>(static_cast<std::uint64_t>(width_) * height_));
  resolve_.set("uZmK", k_);
  resolve_.set("uZmThickness", ctx.zThickness);
  runResolvePass(ctx, resolve_, Operation{op.name, op.glslFile, nullptr});
}

Stats KBufferZThicknessMerge::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = "spinlock";
  return s;
}

std::vector<std::uint32_t> KBufferZThicknessMerge::capacityMap() const {
  return std::vector<std::uint32_t>(static_cast<std::size_t>(width_) * height_, k_);
}

}  // namespace mfr
