// [Depth complexity — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment Rendering",
// Computer Graphics Forum 39(2), 2020, §2.] Counts every fragment a pixel receives: n(p), the
// per-pixel depth complexity (viewer heat map, budget features). Colour writes are off.
#include "common/bindings.h"

layout(std430, binding = MFR_SSBO_AUX) buffer DepthComplexityCounts { uint dcCounts[]; };
uniform int uDcWidth;

void main() { atomicAdd(dcCounts[uint(gl_FragCoord.y) * uint(uDcWidth) + uint(gl_FragCoord.x)], 1u); }
