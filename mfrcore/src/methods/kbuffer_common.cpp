#include "kbuffer_common.hpp"

#include <algorithm>
#include <sstream>

#include <epoxy/gl.h>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "method_util.hpp"

namespace mfr {

KBufferSync kbufferSync(const std::string& choice) {
  if (choice != "interlock") return {"spinlock", {}};
  const gl::ContextInfo info = gl::queryContextInfo();
  if (info.fragmentShaderInterlock) {
    // The GLSL spelling differs per extension; prefer the ARB one.
    if (epoxy_has_gl_extension("GL_ARB_fragment_shader_interlock"))
      return {"interlock", {{"MFR_SYNC_INTERLOCK", "1"}, {"MFR_INTERLOCK_ARB", "1"}}};
    if (epoxy_has_gl_extension("GL_NV_fragment_shader_interlock"))
      return {"interlock", {{"MFR_SYNC_INTERLOCK", "1"}, {"MFR_INTERLOCK_NV", "1"}}};
    if (epoxy_has_gl_extension("GL_INTEL_fragment_shader_ordering"))
      return {"interlock", {{"MFR_SYNC_INTERLOCK", "1"}, {"MFR_INTERLOCK_INTEL", "1"}}};
  }
  throw Error("--param sync=interlock", "not supported by this OpenGL driver");
}

std::vector<ParamSpec> kbufferParams(bool culling, bool revised, const std::string& kDefault) {
  std::vector<ParamSpec> p{
      {"k",
       "Fragments per pixel (k)",
       ParamSpec::Type::Int,
       kDefault,
       1,
       256,
       {},
       "capacity per pixel: the k nearest fragments are kept"},
      {"sync",
       "Per-pixel synchronisation",
       ParamSpec::Type::Choice,
       "spinlock",
       0,
       0,
       {"spinlock", "interlock"},
       "spinlock: semaphore image + imageAtomicExchange, bounded retries; interlock: "
       "ARB_fragment_shader_interlock where the driver has it"},
      {"spin_limit",
       "Spin-lock attempts",
       ParamSpec::Type::Int,
       "1024",
       1,
       4096,
       {},
       "lock attempts per fragment before it is dropped (counted in lockFailures)"},
      {"tail",
       "Accumulate the tail",
       ParamSpec::Type::Bool,
       "false",
       0,
       0,
       {},
       "accumulate the fragments beyond the k nearest per pixel (Σ colour·α, Σ α, count) for hybrid "
       "transparency"}};
  if (culling)
    p.push_back({"culling",
                 "Cull against the maximum",
                 ParamSpec::Type::Bool,
                 "true",
                 0,
                 0,
                 {},
                 "reject fragments behind the pixel's current k-th nearest before taking the lock"});
  if (revised)
    p.push_back({"revised",
                 "Direct insertion of the first k-1",
                 ParamSpec::Type::Bool,
                 "false",
                 0,
                 0,
                 {},
                 "k+-buffer §3.2.1: the first k-1 fragments of a pixel take slots from a per-pixel atomic "
                 "counter, without the lock or a maximum search"});
  return p;
}

void KBufferFamily::configureCommon(int width, int height, const Params& params, const std::string& storeFolder,
                                    const std::string& resolveFolder, const gl::Defines& storeDefines) {
  sync_ = kbufferSync(params.text("sync"));
  spinLimit_ = static_cast<std::uint32_t>(params.integer("spin_limit"));
  tail_ = externalPixelState_ || params.flag("tail");  // the variable-k buffers always keep the tail
  folder_ = resolveFolder;
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    locks_.reset();
    tailBuffer_.reset();
    entries_.reset();
    aux_.reset();
    slots_ = 0;
    auxBytes_ = 0;
  }
  // The semaphore image exists only when the spin lock runs (interlock needs none). Members that
  // keep locks and tail in their own per-pixel arena (externalPixelState_) allocate neither.
  const bool ownLocks = sync_.name == "spinlock" && !externalPixelState_;
  if (ownLocks && !locks_) locks_ = gl::createTexture2D(GL_R32UI, width_, height_);
  if (!ownLocks) locks_.reset();
  const bool ownTail = tail_ && !externalPixelState_;
  // The tail (20 bytes a pixel, more than one 8-byte slot) is one storage block too (a review).
  if (ownTail)
    requireStorageFits("--method " + info().name,
                       "its per-pixel tail of " + std::to_string(kTailBytesPerPixel) + " bytes", pixels(),
                       maxStorageElements(kTailBytesPerPixel), kTailBytesPerPixel, "; a smaller --size needs less");
  if (ownTail && !tailBuffer_) tailBuffer_ = gl::createBuffer(pixels() * kTailBytesPerPixel);
  if (!ownTail) tailBuffer_.reset();
  if (!counters_) counters_ = gl::createBuffer(kCounterBytes);

  gl::Defines defines = storeDefines;
  defines.insert(sync_.defines.begin(), sync_.defines.end());
  if (externalPixelState_ && sync_.name == "spinlock") defines.emplace("MFR_KB_LOCKS_IN_BUFFER", "1");
  if (tail_) defines.emplace("MFR_KB_TAIL", "1");
  std::string key = storeFolder;
  for (const auto& [k, v] : defines) key += ";" + k + "=" + v;
  auto it = storePrograms_.find(key);
  if (it == storePrograms_.end())
    it = storePrograms_
             .emplace(key, gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"},
                                        {GL_FRAGMENT_SHADER, "methods/" + storeFolder + "/store.geom.frag"}},
                                       defines))
             .first;
  store_ = &it->second;
}

void KBufferFamily::allocateSlots(std::uint64_t slots, std::uint64_t auxBytes) {
  slots = std::max<std::uint64_t>(slots, 1);
  const std::uint64_t limit = std::min<std::uint64_t>(maxStorageElements(kEntryBytes), 0xFFFFFFFFull);
  if (slots > limit) {
    std::ostringstream why;
    why << width_ << "x" << height_ << " pixels need " << slots << " slots x 8 bytes, more than the largest shader "
        << "storage block of this GL context holds (" << limit << " slots)";
    // A method that chooses its k (kplus-dynamic, the budget methods) is named instead of a
    // "--param k=36" the user never gave (a bug hunt); the slots say how many it asked for.
    const MethodInfo& method = info();
    const bool userK =
        std::any_of(method.params.begin(), method.params.end(), [](const ParamSpec& p) { return p.name == "k"; });
    throw Error(userK ? "--param k=" + std::to_string(k_) : "--method " + method.name, why.str());
  }
  if (slots != slots_ || !entries_) {
    entries_ = gl::createBuffer(slots * kEntryBytes);
    slots_ = slots;
  }
  if (auxBytes != auxBytes_ || (auxBytes > 0 && !aux_)) {
    aux_ = auxBytes > 0 ? gl::createBuffer(auxBytes) : gl::Buffer();
    auxBytes_ = auxBytes;
  }
}

void KBufferFamily::setCommonUniforms(const gl::Program& program) const {
  program.use();
  program.set("uKbWidth", width_);
  program.set("uKbPixels", static_cast<unsigned>(pixels()));
  program.set("uKbK", k_);
  program.set("uSpinLimit", spinLimit_);
  if (externalPixelState_) program.set("uKbLockWidth", width_);
}

void KBufferFamily::beginStore() {
  stats_ = Stats{};
  const GLuint zero = 0;
  const GLuint empty[2] = {0u, 0x7F800000u};  // colour 0, depth +inf (KB_EMPTY)
  glClearNamedBufferData(entries_.id(), GL_RG32UI, GL_RG_INTEGER, GL_UNSIGNED_INT, empty);
  glClearNamedBufferData(counters_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  if (aux_) glClearNamedBufferData(aux_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  if (tailBuffer_) glClearNamedBufferData(tailBuffer_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  if (locks_) glClearTexImage(locks_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, entries_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_COUNTER, counters_.id());
  if (aux_) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, aux_.id());
  if (tailBuffer_) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_TAIL, tailBuffer_.id());
  if (locks_) glBindImageTexture(MFR_IMAGE_LOCKS, locks_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
}

void KBufferFamily::drawStore(const FrameContext& ctx, const char* pass) {
  GeometryPassState state;  // no depth test, no culling, colour writes off
  setCommonUniforms(*store_);
  ctx.timer.begin(pass);
  ctx.scene.draw(*store_, ctx.frame);
  ctx.timer.end();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  stats_.passes += 1;
}

void KBufferFamily::finishStore(std::uint64_t extraBytes) {
  std::uint32_t c[3] = {0, 0, 0};
  glGetNamedBufferSubData(counters_.id(), 0, sizeof c, c);
  stats_.fragmentsGenerated = c[0];
  stats_.fragmentsDropped = c[1];
  stats_.lockFailures = c[2];
  stats_.fragmentsStored = c[0] - std::min<std::uint64_t>(c[0], std::uint64_t{c[1]} + c[2]);
  // Keeping only the k nearest is the k-buffer contract, not an overflow: fragments beyond k are
  // counted in fragmentsDropped, lost lock attempts in lockFailures.
  stats_.overflow = false;
  stats_.kMin = stats_.kMax = k_;
  const std::uint64_t lockBytes = locks_ ? pixels() * 4 : 0;
  const std::uint64_t tailBytes = tailBuffer_ ? pixels() * kTailBytesPerPixel : 0;
  stats_.bytesAllocated = slots_ * kEntryBytes + lockBytes + auxBytes_ + kCounterBytes + tailBytes + extraBytes;
  stats_.bytesUsed = stats_.bytesAllocated - (slots_ - std::min(slots_, stats_.fragmentsStored)) * kEntryBytes;
  stats_.notes.emplace_back("k", std::to_string(k_));
  if (tail_) stats_.notes.emplace_back("tail", "accumulated (MFR_SSBO_TAIL)");
}

void KBufferFamily::resolve(const FrameContext& ctx, const Operation& op) {
  const gl::Program& program = resolve_.get(folder_, op, resolveDefines_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_NODES, entries_.id());
  if (tailBuffer_) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_TAIL, tailBuffer_.id());
  setCommonUniforms(program);
  program.set("uMaxListLength", k_);
  runResolvePass(ctx, program, op);
}

Stats KBufferFamily::stats() const {
  Stats s = stats_;
  s.method = info().name;
  s.sync = sync_.name;
  return s;
}

std::vector<std::uint32_t> KBufferFamily::capacityMap() const {
  return std::vector<std::uint32_t>(static_cast<std::size_t>(pixels()), k_);
}

std::vector<KBufferTail> KBufferFamily::readTail() const {
  std::vector<KBufferTail> out;
  if (!tailBuffer_) return out;
  const std::size_t n = static_cast<std::size_t>(pixels());
  std::vector<std::uint32_t> raw(n * 5);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(tailBuffer_.id(), 0, static_cast<GLsizeiptr>(raw.size() * 4), raw.data());
  out.resize(n);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const std::size_t src = (static_cast<std::size_t>(height_ - 1 - y) * width_ + x) * 5;  // GL rows bottom-up
      KBufferTail& t = out[static_cast<std::size_t>(y) * width_ + x];
      t.colorAlpha[0] = raw[src];
      t.colorAlpha[1] = raw[src + 1];
      t.colorAlpha[2] = raw[src + 2];
      t.alpha = raw[src + 3];
      t.count = raw[src + 4];
    }
  return out;
}

}  // namespace mfr
