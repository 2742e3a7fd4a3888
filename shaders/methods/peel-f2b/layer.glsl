// Front-to-back depth peeling: Everitt, "Interactive Order-Independent Transparency", NVIDIA
// technical report, 2001. The peeled layer every pass produces: one 8-byte payload per pixel in an
// RG32UI texture (packed RGBA8 colour, depth bits), MFR_NIL depth bits where the pass found no
// fragment. Storing the exact bits keeps the next pass's "strictly behind" test on the very float
// the rasteriser generated, and gives the dump operation the same payload every method stores.
#include "common/bindings.h"
#include "common/payload.glsl"

bool peelPresent(uvec2 layer) { return layer.y != MFR_NIL; }
