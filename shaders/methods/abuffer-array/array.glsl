// A-buffer with fixed-size per-pixel arrays: Liu, Huang, Liu, Wu, "FreePipe: a Programmable
// Parallel Rendering Architecture for Efficient Multi-Fragment Effects", I3D 2010; Crassin,
// "Fast and Accurate Single-Pass A-Buffer using OpenGL 4.0+" (2010).
// Storage shared by the passes: a per-pixel r32ui arrival counter and uSlots fragments per pixel.
// Layout slot-major (slot s of pixel p at s·uPixels + p, Crassin's "pages"): neighbouring pixels
// reading the same slot in the resolve touch neighbouring memory.
#include "common/bindings.h"
#include "common/payload.glsl"

layout(std430, binding = MFR_SSBO_NODES) buffer ArrayFragments { uvec2 arrayFragments[]; };
uniform uint uSlots;   // capacity per pixel
uniform uint uPixels;  // width · height
uniform int uWidth;

uint pixelIndex(ivec2 p) { return uint(p.y) * uint(uWidth) + uint(p.x); }
