// k+-buffer on S-buffer storage, K+B-AB_SB (Vasilakis, Papaioannou, Fudos, "k+-buffer: An
// Efficient, Memory-Friendly and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015, Alg. 3):
// bounded count pass. Each pixel counts its fragments up to k only, so the prefix sum that follows
// allocates min(n(p), k) slots per pixel: no memory for pixels that never fill k.
// The bound without a retry loop: a fragment that sees the counter below k increments it; if its
// increment went past k (a race with other fragments of the pixel) it clamps with atomicMin(k).
// The last operation on a counter is either an increment from below k or a clamp, so the final
// value is exactly min(n(p), k). Colour writes are off.
#include "common/fragment.glsl"
#include "common/kbuffer_array.glsl"

layout(std430, binding = MFR_SSBO_AUX) coherent buffer KBufferBoundedCounts { uint kbCounts[]; };

void main() {
  uint pixel = kbPixel(ivec2(gl_FragCoord.xy));
  if (kbCounts[pixel] < uKbK && atomicAdd(kbCounts[pixel], 1u) >= uKbK) atomicMin(kbCounts[pixel], uKbK);
}
