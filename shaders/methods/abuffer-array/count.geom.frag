// A-buffer with fixed-size per-pixel arrays (FreePipe, Liu et al., I3D 2010): count pass of the
// optional automatic sizing (slots=0): per-pixel arrival counts, whose maximum sizes the arrays.
#include "common/fragment.glsl"

layout(r32ui, binding = MFR_IMAGE_COUNTS) uniform coherent uimage2D uCounts;

void main() { imageAtomicAdd(uCounts, ivec2(gl_FragCoord.xy), 1u); }
