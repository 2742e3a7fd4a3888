#include "variable_k_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include <epoxy/gl.h>

#include "budget/glsl_shared.hpp"
#include "common/bindings.h"
#include "mfr/budget/k_allocation.hpp"
#include "mfr/error.hpp"
#include "method_util.hpp"

namespace mfr {

namespace {

// Word offsets of the budget state SSBO (shaders/budget/arena.glsl).
enum StateWord : std::uint32_t {
  kTotal = 0,
  kNonEmpty = 1,
  kImageNear = 2,
  kImageFar = 3,
  kBudgetSlots = 4,
  kAllocMode = 5,
  kLo = 6,
  kHi = 7,
  kSumLo = 8,
  kMultiFragment = 9,
  kKMin = 25,
  kKMax = 26,
  kExactSlots = 27,
  kStateWords = 32,
};

std::string mibText(std::uint64_t bytes) {
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << static_cast<double>(bytes) / (1024.0 * 1024.0);
  return s.str();
}

}  // namespace

std::vector<ParamSpec> VariableKBuffer::budgetParams() {
  return {{"budget_mib",
           "Memory budget M (MiB)",
           ParamSpec::Type::Float,
           "16",
           0,
           65536,
           {},
           "GPU memory for all of the method's buffers; k(p) is allocated so that it is used up",
           true},
          {"sync",
           "Per-pixel synchronisation",
           ParamSpec::Type::Choice,
           "spinlock",
           0,
           0,
           {"spinlock", "interlock"},
           "spinlock: a semaphore word per pixel + atomicExchange, bounded retries; interlock: "
           "ARB_fragment_shader_interlock where the driver has it"},
          {"spin_limit",
           "Spin-lock attempts",
           ParamSpec::Type::Int,
           "1024",
           1,
           4096,
           {},
           "lock attempts per fragment before it is dropped (counted in lockFailures)"},
          {"culling",
           "Cull against the maximum",
           ParamSpec::Type::Bool,
           "true",
           0,
           0,
           {},
           "reject fragments behind the pixel's current k(p)-th nearest before taking the lock"},
          {"exact_tail",
           "No slot for a pixel's last fragment",
           ParamSpec::Type::Bool,
           "true",
           0,
           0,
           {},
           "k(p) <= n(p) - 1 until every pixel has n - 1 slots: hybrid transparency composites a "
           "one-fragment tail exactly (off: the papers' bounds 1 <= k(p) <= n(p))"},
          {"tail_runs",
           "No slots for a final run of one colour",
           ParamSpec::Type::Bool,
           "true",
           0,
           0,
           {},
           "with exact_tail: k(p) <= max(1, n - m) for the m farthest fragments of one RGBA, a tail hybrid "
           "transparency composites exactly (three more geometry passes find m)",
           false,
           "exact_tail=true"}};
}

void VariableKBuffer::configure(int width, int height, const Params& params) {
  externalPixelState_ = true;
  culling_ = params.flag("culling");
  exactTail_ = params.flag("exact_tail");
  tailRuns_ = params.flag("tail_runs");
  budgetText_ = params.text("budget_mib");
  budgetBytes_ = static_cast<std::uint64_t>(std::floor(params.real("budget_mib") * 1024.0 * 1024.0));
  configureMember(params);
  gl::Defines defines{{"MFR_KB_VARIABLE", "1"}};
  if (culling_) defines.emplace("MFR_KB_CULLING", "1");
  resolveDefines_ = {{"MFR_KB_VARIABLE", "1"}};
  const bool resized = width != width_ || height != height_;
  configureCommon(width, height, params, "kplus-array", folder(), defines);

  GLint alignment = 0;
  glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &alignment);
  if (alignment > 256) throw Error(info().name, "the GL driver aligns storage buffer ranges to more than 256 bytes");

  const VariableKLayout layout = variableKLayout(pixels(), memberFixedBytes());
  if (budgetBytes_ < layout.bytes(1))
    throw Error("--param budget_mib=" + budgetText_,
                "below what " + info().name + " needs at " + std::to_string(width) + "x" + std::to_string(height) +
                    " for its per-pixel buffers and one fragment slot (" + mibText(layout.bytes(1)) +
                    " MiB = " + std::to_string(layout.bytes(1)) + " bytes)");
  // The arena (per-pixel words, about 28 bytes a pixel) is bound whole as one storage block (a review).
  requireStorageFits("--method " + info().name, "its per-pixel arena", layout.arenaWords, maxStorageElements(4), 4,
                     "; a smaller --size needs less");
  if (resized || !arena_ || layout.arenaWords != layout_.arenaWords) arena_ = gl::createBuffer(layout.arenaBytes());
  layout_ = layout;
  if (!state_) state_ = gl::createBuffer(kVariableKStateBytes);
  if (!imageStats_.id()) {
    search_ = gl::Program({{GL_COMPUTE_SHADER, "budget/alloc_search.comp"}});
    narrow_ = gl::Program({{GL_COMPUTE_SHADER, "budget/alloc_narrow.comp"}});
    assign_ = gl::Program({{GL_COMPUTE_SHADER, "budget/alloc_assign.comp"}});
    finish_ = gl::Program({{GL_COMPUTE_SHADER, "budget/alloc_finish.comp"}});
    gl::Defines statsDefines;
    if (needsDepthRange()) statsDefines.emplace("MFR_VK_DEPTH_RANGE", "1");
    imageStats_ = gl::Program({{GL_COMPUTE_SHADER, "budget/image_stats.comp"}}, statsDefines);
    runColor_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "budget/tail_run_color.geom.frag"}});
    runBreak_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "budget/tail_run_break.geom.frag"}});
    runLength_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "budget/tail_run_length.geom.frag"}});
    runSum_ = gl::Program({{GL_COMPUTE_SHADER, "budget/tail_run_sum.comp"}});
  }
}

void VariableKBuffer::setArenaUniforms(const gl::Program& program) const {
  program.use();
  program.set("uVkPixels", static_cast<unsigned>(pixels()));
  program.set("uVkWidth", width_);
  program.set("uVkLockBase", static_cast<unsigned>(layout_.lockBase));
  program.set("uVkTailBase", static_cast<unsigned>(layout_.tailBase));
  program.set("uVkStride", static_cast<unsigned>(layout_.stride));
  program.set("uVkKBase", static_cast<unsigned>(layout_.kBase));
}

void VariableKBuffer::bindArena() const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_ARENA, arena_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_BUDGET, state_.id());
}

void VariableKBuffer::clearArena(std::uint64_t base, std::uint64_t words, std::uint32_t value) const {
  glClearNamedBufferSubData(arena_.id(), GL_R32UI, static_cast<GLintptr>(4 * base), static_cast<GLsizeiptr>(4 * words),
                            GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
}

void VariableKBuffer::dispatchPixels(const gl::Program& program, std::uint32_t groupSize) const {
  const std::uint64_t groups = (pixels() + groupSize - 1) / groupSize;
  const auto x = static_cast<std::uint32_t>(std::min<std::uint64_t>(groups, 65535));
  const auto y = static_cast<std::uint32_t>((groups + x - 1) / x);
  program.use();
  glDispatchCompute(x, y, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void VariableKBuffer::capture(const FrameContext& ctx) {
  // 1. Feature passes.
  std::uint32_t state[kStateWords] = {};
  state[kImageNear] = MFR_ALLOC_INFINITY_BITS;
  state[kKMin] = 0xFFFFFFFFu;
  glNamedBufferSubData(state_.id(), 0, sizeof state, state);
  clearArena(layout_.lockBase, pixels(), 0);
  clearFeatures();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  bindArena();
  std::uint32_t featurePasses = 0;
  {
    GeometryPassState geometry;
    featurePasses = drawFeatures(ctx);
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

  // 2. Image sums, read back once: F and the slot buffer's size.
  setArenaUniforms(imageStats_);
  ctx.timer.begin("image sums");
  dispatchPixels(imageStats_, 256);
  ctx.timer.end();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(state_.id(), 0, 4 * (kMultiFragment + 1), state);
  totalFragments_ = state[kTotal];
  nonEmpty_ = state[kNonEmpty];
  const std::uint64_t multiFragment = state[kMultiFragment];
  const std::uint64_t budgetSlots = layout_.slotBudget(budgetBytes_);
  slotsF_ = std::min<std::uint64_t>(budgetSlots, totalFragments_);
  const auto slotsWord = static_cast<std::uint32_t>(slotsF_);  // dkb's features read F
  glNamedBufferSubData(state_.id(), 4 * kBudgetSlots, sizeof slotsWord, &slotsWord);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

  // 3. Importance.
  bindArena();
  ctx.timer.begin("importance");
  computeImportance(ctx);
  ctx.timer.end();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  if (keepImportance_) {
    std::vector<std::uint32_t> raw(static_cast<std::size_t>(pixels()));
    glGetNamedBufferSubData(arena_.id(), static_cast<GLintptr>(4 * layout_.tailBase),
                            static_cast<GLsizeiptr>(4 * raw.size()), raw.data());
    importance_.resize(raw.size());
    std::memcpy(importance_.data(), raw.data(), 4 * raw.size());
    counts_.resize(raw.size());
    glGetNamedBufferSubData(arena_.id(), static_cast<GLintptr>(4 * layout_.lockBase),
                            static_cast<GLsizeiptr>(4 * counts_.size()), counts_.data());
  }

  // 3b. Tail runs, and with them the bounds of k(p).
  const bool runs = exactTail_ && tailRuns_;
  const std::uint64_t exactSlots = runs ? findTailRuns(ctx) : totalFragments_ - multiFragment;
  if (runs) featurePasses += 3;
  tailRunMap_.clear();
  if (runs && keepImportance_) {
    tailRunMap_.resize(static_cast<std::size_t>(pixels()));
    glGetNamedBufferSubData(arena_.id(), static_cast<GLintptr>(4 * layout_.kBase),
                            static_cast<GLsizeiptr>(4 * tailRunMap_.size()), tailRunMap_.data());
  }
  const AllocationBounds bounds = allocationBounds(slotsF_, nonEmpty_, exactSlots, exactTail_, runs);
  const std::uint32_t mode = bounds.mode;
  const bool allFit = totalFragments_ <= budgetSlots;
  const std::uint32_t search[5] = {static_cast<std::uint32_t>(slotsF_), mode, allFit ? MFR_ALLOC_INFINITY_BITS : 0u,
                                   MFR_ALLOC_INFINITY_BITS,
                                   static_cast<std::uint32_t>(allFit ? totalFragments_ : bounds.sumAtZero)};
  glNamedBufferSubData(state_.id(), 4 * kBudgetSlots, sizeof search, search);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

  // 4. Allocation.
  allocate(ctx);

  // 5. Store: the lock words and the tail sums take over their arena regions.
  allocateSlots(slotsF_, 0);
  beginStore();
  clearArena(layout_.lockBase, pixels(), 0);
  clearArena(layout_.tailBase, 5 * pixels(), 0);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, arena_.id(), static_cast<GLintptr>(4 * layout_.kBase),
                    static_cast<GLsizeiptr>(4 * (pixels() + 1)));
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_TAIL, arena_.id(), static_cast<GLintptr>(4 * layout_.tailBase),
                    static_cast<GLsizeiptr>(4 * 5 * pixels()));
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_LOCKS, arena_.id(), static_cast<GLintptr>(4 * layout_.lockBase),
                    static_cast<GLsizeiptr>(4 * pixels()));
  drawStore(ctx);

  // 6. Statistics: k range from the allocation pass, memory of every buffer.
  glGetNamedBufferSubData(state_.id(), 0, sizeof state, state);
  k_ = std::max<std::uint32_t>(state[kKMax], 1);
  finishStore(layout_.arenaBytes() + layout_.scanScratchBytes + kVariableKStateBytes + memberFixedBytes());
  stats_.passes += featurePasses;
  stats_.kMin = nonEmpty_ > 0 ? state[kKMin] : 0;
  stats_.kMax = nonEmpty_ > 0 ? state[kKMax] : 0;
  stats_.notes.clear();
  stats_.notes.emplace_back("budget", budgetText_ + " MiB = " + std::to_string(budgetBytes_) + " bytes");
  stats_.notes.emplace_back("F(M)", std::to_string(budgetSlots) + " slots");
  stats_.notes.emplace_back("slots assigned",
                            std::to_string(slotsF_) + " of " + std::to_string(totalFragments_) + " fragments" +
                                ((mode & MFR_ALLOC_FLOOR_ONE) == 0 ? " (k = 0 allowed: F < non-empty pixels)" : ""));
  stats_.notes.emplace_back("importance", describeImportance());
  stats_.notes.emplace_back("culling", culling_ ? "on" : "off");
  const std::string bound = runs ? "max(1, n - m), m the final run of one colour" : "n - 1";
  stats_.notes.emplace_back("exact tail", !exactTail_                     ? "off (1 <= k <= n)"
                                          : (mode & MFR_ALLOC_FILL) != 0u ? "every pixel exact (k >= " + bound + ")"
                                                                          : "k <= " + bound);
  // The least budget at which this frame's hybrid image is exact: Σ max(1, n − m) slots with the
  // bound, every fragment without it.
  const std::uint64_t exactAt = exactTail_ ? exactSlots : totalFragments_;
  stats_.notes.emplace_back("exact at", ">= " + mibText(layout_.bytes(std::max<std::uint64_t>(exactAt, 1))) + " MiB (" +
                                            std::to_string(exactAt) + " slots)");
}

std::uint64_t VariableKBuffer::findTailRuns(const FrameContext& ctx) {
  ctx.timer.begin("tail runs");
  clearArena(layout_.tailBase + 3 * layout_.stride, 2 * layout_.stride, 0);  // T(3), T(4)
  clearArena(layout_.kBase, pixels() + 1, 0);                                // K: m(p)
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  bindArena();
  {
    GeometryPassState geometry;
    setArenaUniforms(runColor_);
    runColor_.set("uVkFarRegion", farthestDepthRegion());
    ctx.scene.draw(runColor_, ctx.frame);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    setArenaUniforms(runBreak_);
    ctx.scene.draw(runBreak_, ctx.frame);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    setArenaUniforms(runLength_);
    ctx.scene.draw(runLength_, ctx.frame);
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  setArenaUniforms(runSum_);
  dispatchPixels(runSum_, 256);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::uint32_t exactSlots = 0;
  glGetNamedBufferSubData(state_.id(), 4 * kExactSlots, sizeof exactSlots, &exactSlots);
  ctx.timer.end();
  return exactSlots;
}

void VariableKBuffer::allocate(const FrameContext& ctx) {
  ctx.timer.begin("allocation");
  bindArena();
  for (const gl::Program* p : {&search_, &narrow_, &assign_, &finish_}) setArenaUniforms(*p);
  for (std::uint32_t round = 0; round < MFR_ALLOC_ROUNDS; ++round) {
    dispatchPixels(search_, 256 * MFR_ALLOC_SEARCH_PIXELS);
    narrow_.use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }
  dispatchPixels(assign_, 256);
  const auto n = static_cast<std::uint32_t>(pixels() + 1);
  scan_.scan(arena_.id(), static_cast<std::uint32_t>(layout_.tailBase + layout_.stride), arena_.id(),
             static_cast<std::uint32_t>(layout_.tailBase + layout_.stride), n);
  bindArena();  // the scan clobbers bindings
  dispatchPixels(finish_, 256);
  scan_.scan(arena_.id(), static_cast<std::uint32_t>(layout_.kBase), arena_.id(),
             static_cast<std::uint32_t>(layout_.kBase), n);
  ctx.timer.end();
}

void VariableKBuffer::resolve(const FrameContext& ctx, const Operation& op) {
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, arena_.id(), static_cast<GLintptr>(4 * layout_.kBase),
                    static_cast<GLsizeiptr>(4 * (pixels() + 1)));
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_TAIL, arena_.id(), static_cast<GLintptr>(4 * layout_.tailBase),
                    static_cast<GLsizeiptr>(4 * 5 * pixels()));
  KBufferFamily::resolve(ctx, op);
}

std::vector<std::uint32_t> VariableKBuffer::capacityMap() const {
  return readCapacities(arena_, pixels(), layout_.kBase);
}

}  // namespace mfr
