// Dynamic k+-buffer (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient, Memory-Friendly and
// Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015): count pass. n(p) per pixel (input of the
// depth-complexity histogram) and the frame's exact fragment total. Colour writes are off.
#include "common/fragment.glsl"
#include "common/kbuffer_array.glsl"

layout(std430, binding = MFR_SSBO_AUX) buffer KDynamicCounts { uint kdCounts[]; };

void main() {
  atomicAdd(kdCounts[kbPixel(ivec2(gl_FragCoord.xy))], 1u);
  atomicAdd(kbGenerated, 1u);
}
