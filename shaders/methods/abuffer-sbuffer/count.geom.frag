// S-buffer (Vasilakis & Fudos, EG 2012 short papers): count pass. Per-pixel fragment counts by
// atomic increment; a compute-shader scan (common/prefix_sum.comp) turns them into offsets.
#include "common/fragment.glsl"
#include "methods/abuffer-sbuffer/sbuffer.glsl"

void main() { atomicAdd(sCounts[pixelIndex(ivec2(gl_FragCoord.xy))], 1u); }
