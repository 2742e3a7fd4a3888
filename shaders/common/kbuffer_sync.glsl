// k+-buffer per-pixel critical section: Vasilakis & Fudos, "k+-buffer: Fragment Synchronized
// k-buffer", I3D 2014, Alg. 1 (spin lock on a per-pixel semaphore), and Vasilakis, Papaioannou,
// Fudos, IEEE TVCG 21(6) 2015 (the same with ARB_fragment_shader_interlock where available).
// Provides main() for every k-buffer store pass; it must be the FIRST include of the pass (the
// interlock #extension has to precede all declarations).
//
// The including pass defines, after this include:
//   void kbBegin();     shades the current fragment into the pass's globals
//   uint kbPrepare();   work outside the critical section: KB_LOCK (needs it), KB_DONE (handled
//                       lock-free, e.g. the revised max-array's direct insertion), KB_REJECT
//                       (culled: nearer fragments already fill the pixel)
//   bool kbReady();     may this fragment enter the critical section yet (spin-lock path only)
//   void kbInsert();    the critical section: the read-modify-write of the pixel's k slots
//   void kbRejected();  bookkeeping of a fragment kbPrepare rejected
//
// Spin lock (the default, works everywhere): imageAtomicExchange(1) on the pixel's r32ui
// semaphore acquires; memoryBarrier() makes the critical section's writes visible before
// imageAtomicExchange(0) releases. The loop carries a done flag and the critical section sits
// inside one iteration: every lane of a SIMT group executes the same loop, the lane that won the
// semaphore finishes and releases in that iteration, the others retry. A spin *inside* the
// branch of the winner ("while (exchange != 0) {} critical; release") can deadlock on GPUs that
// run the diverged lanes of one warp in lock step: the losers spin forever while the winner,
// masked off, never reaches its release. The loop is bounded by uSpinLimit; a fragment that never
// gets the lock is dropped and counted (kbLockFailures), so no input can hang the GPU.
// Interlock: beginInvocationInterlock/endInvocationInterlock (must be called from main(), outside
// any control flow) serialise overlapping fragments of one pixel in hardware; no semaphore image.
#ifdef MFR_SYNC_INTERLOCK
#if defined(MFR_INTERLOCK_ARB)
#extension GL_ARB_fragment_shader_interlock : require
#define KB_INTERLOCK_BEGIN() beginInvocationInterlockARB()
#define KB_INTERLOCK_END() endInvocationInterlockARB()
layout(pixel_interlock_ordered) in;
#elif defined(MFR_INTERLOCK_NV)
#extension GL_NV_fragment_shader_interlock : require
#define KB_INTERLOCK_BEGIN() beginInvocationInterlockNV()
#define KB_INTERLOCK_END() endInvocationInterlockNV()
layout(pixel_interlock_ordered) in;
#elif defined(MFR_INTERLOCK_INTEL)
#extension GL_INTEL_fragment_shader_ordering : require
#define KB_INTERLOCK_BEGIN() beginFragmentShaderOrderingINTEL()
#define KB_INTERLOCK_END()
#else
#error "MFR_SYNC_INTERLOCK needs MFR_INTERLOCK_ARB, _NV or _INTEL"
#endif
#endif

#include "common/bindings.h"

const uint KB_LOCK = 0u;
const uint KB_DONE = 1u;
const uint KB_REJECT = 2u;

void kbBegin();
uint kbPrepare();
bool kbReady();
void kbInsert();
void kbRejected();
void kbLockFailed();

#ifndef MFR_SYNC_INTERLOCK
uniform uint uSpinLimit;  // attempts per fragment (≤ 4096: llvmpipe loop-bound trap, see bindings.h)
#ifdef MFR_KB_LOCKS_IN_BUFFER
// The same semaphore as one uint per pixel of an SSBO (atomicExchange): the variable-k buffers keep
// it in their per-pixel arena, whose words held other per-pixel data before the store pass.
layout(std430, binding = MFR_SSBO_LOCKS) coherent buffer KBufferLockWords { uint kbLockWords[]; };
uniform int uKbLockWidth;
uint kbLockWord(ivec2 p) { return uint(p.y) * uint(uKbLockWidth) + uint(p.x); }
bool kbTryLock(ivec2 p) { return atomicExchange(kbLockWords[kbLockWord(p)], 1u) == 0u; }
void kbUnlock(ivec2 p) { atomicExchange(kbLockWords[kbLockWord(p)], 0u); }
#else
layout(r32ui, binding = MFR_IMAGE_LOCKS) uniform coherent uimage2D uKbLocks;
bool kbTryLock(ivec2 p) { return imageAtomicExchange(uKbLocks, p, 1u) == 0u; }
void kbUnlock(ivec2 p) { imageAtomicExchange(uKbLocks, p, 0u); }
#endif
#endif

void main() {
#ifndef MFR_SYNC_INTERLOCK
  // Helper invocations (quad padding) have no side effects: nothing to capture, no lock to spin on.
  // (Under interlock no return may precede beginInvocationInterlock; there they pass through.)
  if (gl_HelperInvocation) return;
#endif
  kbBegin();
  uint action = kbPrepare();
#ifdef MFR_SYNC_INTERLOCK
  KB_INTERLOCK_BEGIN();
  if (action == KB_LOCK) kbInsert();
  KB_INTERLOCK_END();
#else
  if (action == KB_LOCK) {
    ivec2 p = ivec2(gl_FragCoord.xy);
    bool done = false;
    for (uint attempt = 0u; attempt < uSpinLimit && !done; ++attempt) {
      if (kbReady() && kbTryLock(p)) {
        kbInsert();
        memoryBarrier();  // the slots' new contents before the release
        kbUnlock(p);
        done = true;
      }
    }
    if (!done) kbLockFailed();
  }
#endif
  if (action == KB_REJECT) kbRejected();
}
