// A-buffer with variable-length contiguous per-pixel arrays: Vasilakis, Fudos, "S-buffer:
// Sparsity-aware Multi-fragment Rendering", Eurographics 2012 Short Papers (also the dynamic
// fragment buffer of Maule, Comba, Torchelsen, Bastos, 2012).
// Storage shared by the passes: per-pixel counts (reused as store cursors), per-pixel offsets
// (exclusive scan of the counts, width·height + 1 entries: offsets[p+1] ends pixel p's range) and
// one fragment buffer of uCapacity fragments in which each pixel owns a contiguous range.
#include "common/bindings.h"
#include "common/payload.glsl"

layout(std430, binding = MFR_SSBO_NODES) buffer SFragments { uvec2 sFragments[]; };
layout(std430, binding = MFR_SSBO_OFFSETS) buffer SOffsets { uint sOffsets[]; };
layout(std430, binding = MFR_SSBO_AUX) buffer SCounts { uint sCounts[]; };
uniform uint uCapacity;  // fragments the buffer holds
uniform int uWidth;

uint pixelIndex(ivec2 p) { return uint(p.y) * uint(uWidth) + uint(p.x); }
