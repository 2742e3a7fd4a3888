// A-buffer with per-pixel linked lists (Yang et al., EGSR 2010): resolve pass. Walks the pixel's
// list (at most the pool size: no unbounded loop even on a corrupted list) and hands it to the
// shared gather/sort/operate driver.
#include "common/bindings.h"
#include "common/payload.glsl"
#include "methods/abuffer-ll/nodes.glsl"

layout(r32ui, binding = MFR_IMAGE_HEADS) uniform readonly uimage2D uHeads;

uint mfrCursorBegin(ivec2 pixel) { return imageLoad(uHeads, pixel).x; }

// A node never links to itself (its next is an older head), so a cursor whose next is itself ends
// the walk. Measured on llvmpipe: without this check every group of pixels walked to the bound
// (resolve time proportional to the bound, not to the lists: 197 ms on the dragon at 512² with
// lists of at most 12, 8 ms with the bound at 64) — so in each group some lane followed such a
// self-link, most likely a lane whose loads are masked and read 0 (node 0 → node 0). With it the
// walk stops there: 6.8 ms.
bool mfrNext(inout uint cursor, out MfrFragment f) {
  if (cursor == MFR_NIL) return false;
  f = MfrFragment(nodeWords[3u * cursor], uintBitsToFloat(nodeWords[3u * cursor + 1u]));
  uint next = nodeWords[3u * cursor + 2u];
  cursor = next == cursor ? MFR_NIL : next;
  return true;
}

#include "common/resolve.glsl"
