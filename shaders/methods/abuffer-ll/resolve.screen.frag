// A-buffer with per-pixel linked lists (Yang et al., EGSR 2010): resolve pass. Walks the pixel's
// list (at most the pool size: no unbounded loop even on a corrupted list) and hands it to the
// shared gather/sort/operate driver.
#include "common/bindings.h"
#include "common/payload.glsl"
#include "methods/abuffer-ll/nodes.glsl"

layout(r32ui, binding = MFR_IMAGE_HEADS) uniform readonly uimage2D uHeads;

uint mfrCursorBegin(ivec2 pixel) { return imageLoad(uHeads, pixel).x; }

bool mfrNext(inout uint cursor, out MfrFragment f) {
  if (cursor == MFR_NIL) return false;
  f = MfrFragment(nodeWords[3u * cursor], uintBitsToFloat(nodeWords[3u * cursor + 1u]));
  cursor = nodeWords[3u * cursor + 2u];
  return true;
}

#include "common/resolve.glsl"
