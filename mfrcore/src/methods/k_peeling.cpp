#include "k_peeling.hpp"

#include <algorithm>
#include <vector>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {

const MethodInfo& KPeeling::info() const {
  static const MethodInfo i = [] {
    std::vector<ParamSpec> params = kbufferParams(false, false);
    std::erase_if(params, [](const ParamSpec& p) { return p.name == "tail"; });  // exact: no tail
    params.push_back({"max_iterations",
                      "Most peeling iterations",
                      ParamSpec::Type::Int,
                      "1024",
                      1,
                      65535,
                      {},
                      "bound on the geometry passes; beyond ceil(max n(p) / k) > this, the farthest fragments are "
                      "dropped and reported as overflow"});
    return MethodInfo{"kpeel",
                      "k-peeling (multi-pass k-buffer)",
                      "Bavoil, Callahan, Lefohn, Comba, Silva: Multi-fragment effects on the GPU using the k-buffer. "
                      "I3D 2007 (multi-pass k-buffer)",
                      true,
                      params,
                      "oit",
                      false,
                      false};
  }();
  return i;
}

void KPeeling::configure(int width, int height, const Params& params) {
  k_ = static_cast<std::uint32_t>(params.integer("k"));
  spinLimit_ = static_cast<std::uint32_t>(params.integer("spin_limit"));
  sync_ = kbufferSync(params.text("sync"));
  maxIterations_ = static_cast<std::uint32_t>(params.integer("max_iterations"));
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * height;
  if (pixels * k_ > maxStorageElements(kEntryBytes))
    throw Error("--param k=" + std::to_string(k_),
                "k slots of 16 bytes per pixel exceed the largest shader storage block");
  // The per-pixel state (32 bytes, more than the entries at k = 1) is one block too (a review).
  requireStorageFits("--method kpeel", "its per-pixel state of " + std::to_string(kPixelStateBytes) + " bytes", pixels,
                     maxStorageElements(kPixelStateBytes), kPixelStateBytes, "; a smaller --size needs less");
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    counts_ = gl::createTexture2D(GL_R32UI, width, height);
    pixelState_ = gl::createBuffer(pixels * kPixelStateBytes);
    entries_.reset();
  }
  if (!entries_ || entriesK_ != k_) {
    entries_ = gl::createBuffer(pixels * k_ * kEntryBytes);
    entriesK_ = k_;
  }
  if (!counters_) counters_ = gl::createBuffer(kCounterBytes);
  if (!count_.id())
    count_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/kpeel/count.geom.frag"}});
  std::string key = "store";
  for (const auto& [n, v] : sync_.defines) key += ";" + n + "=" + v;
  auto it = programs_.find(key);
  if (it == programs_.end())
    it = programs_
             .emplace(key, gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"},
                                        {GL_FRAGMENT_SHADER, "methods/kpeel/store.geom.frag"}},
                                       sync_.defines))
             .first;
  store_ = &it->second;
}

const gl::Program& KPeeling::peelProgram(const Operation& op, bool carry) {
  const std::string key = "peel;" + op.name + ";" + std::to_string(k_) + (carry ? ";carry" : "");
  auto it = programs_.find(key);
  if (it == programs_.end()) {
    gl::Defines defines{{"MFR_OP_FILE", "\"" + op.glslFile + "\""}, {"KP_LOCAL", std::to_string(k_)}};
    if (carry) defines.emplace("MFR_KPEEL_CARRY", "1");
    it = programs_
             .emplace(key, gl::Program({{GL_VERTEX_SHADER, "common/fullscreen.vert"},
                                        {GL_FRAGMENT_SHADER, "methods/kpeel/peel.screen.frag"}},
                                       defines))
             .first;
  }
  return it->second;
}

void KPeeling::capture(const FrameContext& ctx) {
  stats_ = Stats{};
  const GLuint zero = 0;
  glClearNamedBufferData(counters_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearTexImage(counts_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  {
    GeometryPassState state;
    glBindImageTexture(MFR_IMAGE_COUNTS, counts_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counters_.id());
    ctx.timer.begin("count");
    ctx.scene.draw(count_, ctx.frame);
    ctx.timer.end();
  }
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  std::uint32_t c[2] = {0, 0};
  glGetNamedBufferSubData(counters_.id(), 0, sizeof c, c);
  stats_.fragmentsGenerated = c[0];
  maxCount_ = c[1];
  stats_.passes = 1;
  // Pixels deeper than max_iterations · k keep only their nearest fragments: count them now, before
  // the resolve reuses the count image as its semaphores.
  const std::uint64_t reach = static_cast<std::uint64_t>(k_) * maxIterations_;
  if (maxCount_ > reach) {
    std::vector<std::uint32_t> counts(static_cast<std::size_t>(width_) * height_);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);  // the count pass wrote it with image atomics
    glGetTextureImage(counts_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(4 * counts.size()),
                      counts.data());
    stats_.overflowPixels = static_cast<std::uint64_t>(
        std::count_if(counts.begin(), counts.end(), [&](std::uint32_t n) { return n > reach; }));
  }
}

void KPeeling::resolve(const FrameContext& ctx, const Operation& op) {
  const bool carry = op.name == "oit";
  if (!carry && op.name != "dump")
    throw Error("--op " + op.name,
                "kpeel composites between its peeling iterations: it supports only the operation oit");
  const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * height_;
  // Fresh frame state: empty slots; pixel state all zero (no threshold yet, nothing composited,
  // OIT colour 0 and opacity 0); semaphores 0 (the count image is reused as the semaphore image).
  const GLuint empty[4] = {0u, 0x7F800000u, 0u, 0u};
  glClearNamedBufferData(entries_.id(), GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT, empty);
  const GLuint zeros[4] = {0u, 0u, 0u, 0u};
  glClearNamedBufferData(pixelState_.id(), GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT, zeros);
  const GLuint zero = 0;
  glClearTexImage(counts_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, entries_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, pixelState_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counters_.id());
  glBindImageTexture(MFR_IMAGE_LOCKS, counts_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  const auto uniforms = [&](const gl::Program& p) {
    p.use();
    p.set("uKbWidth", width_);
    p.set("uKbPixels", static_cast<unsigned>(pixels));
    p.set("uKbK", k_);
    p.set("uSpinLimit", spinLimit_);
  };

  const std::uint32_t needed = std::max<std::uint32_t>(1, (maxCount_ + k_ - 1) / k_);
  const std::uint32_t iterations = std::min(needed, maxIterations_);
  const gl::Program& peel = peelProgram(op, carry);
  const gl::VertexArray vao = gl::createVertexArray();
  for (std::uint32_t it = 0; it < iterations; ++it) {
    {
      GeometryPassState state;
      uniforms(*store_);
      ctx.timer.begin("store");
      ctx.scene.draw(*store_, ctx.frame);
      ctx.timer.end();
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    {
      GeometryPassState state;  // the peel pass writes buffers only
      uniforms(peel);
      peel.set("uIteration", it);
      peel.set("uBackground", ctx.background);
      if (op.bind) op.bind(peel);
      glBindVertexArray(vao.id());
      ctx.timer.begin("peel");
      glDrawArrays(GL_TRIANGLES, 0, 3);
      ctx.timer.end();
      glBindVertexArray(0);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }
  stats_.passes = 1 + iterations;

  if (carry) {
    const gl::Program& program = final_.get("kpeel", op);
    uniforms(program);
    runResolvePass(ctx, program, op);
  }

  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::uint32_t c[4] = {0, 0, 0, 0};
  glGetNamedBufferSubData(counters_.id(), 0, sizeof c, c);
  stats_.fragmentsStored = c[2];
  stats_.lockFailures = c[3];
  stats_.fragmentsDropped = stats_.fragmentsGenerated - std::min<std::uint64_t>(stats_.fragmentsGenerated, c[2]);
  stats_.overflow = stats_.fragmentsDropped > 0;
  stats_.kMin = stats_.kMax = k_;
  stats_.bytesAllocated = pixels * (k_ * kEntryBytes + kPixelStateBytes + kCountBytes) + kCounterBytes;
  stats_.bytesUsed = stats_.bytesAllocated;
  stats_.notes.emplace_back("k", std::to_string(k_));
  stats_.notes.emplace_back(
      "iterations", std::to_string(iterations) +
                        (iterations < needed ? " (max_iterations; " + std::to_string(needed) + " needed)" : ""));
  stats_.notes.emplace_back("max depth complexity", std::to_string(maxCount_));
  stats_.notes.emplace_back("ties", "ordered by (depth, object id, primitive id): exact at equal depths");
}

Stats KPeeling::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = sync_.name;
  return s;
}

}  // namespace mfr
