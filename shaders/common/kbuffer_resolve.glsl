// Resolve pass of the k-buffer family (Bavoil et al., I3D 2007; Vasilakis, Papaioannou, Fudos,
// IEEE TVCG 21(6) 2015): walks the pixel's at most k slots, skipping empty ones (+inf depth), and
// hands them to the shared gather/sort/operate driver (common/resolve.glsl sorts them: the
// k+-buffer's max-array and max-heap capture unsorted; the classic k-buffer's array is already
// sorted, which the driver's insertion sort passes through in k steps).
#define KB_ACCESS readonly
#include "common/kbuffer_array.glsl"

uint gResolvePixel, gResolveBase, gResolveStride, gResolveK;

uint mfrCursorBegin(ivec2 pixel) {
  gResolvePixel = kbPixel(pixel);
  gResolveBase = kbBase(gResolvePixel);
  gResolveStride = kbStride(gResolvePixel);
  gResolveK = min(kbCapacity(gResolvePixel), uKbK);
  return 0u;
}

// One exit, the cursor copied in and out explicitly: NVIDIA's compiler (driver 580, H200) ran the
// earlier form (a for loop over the inout cursor with a return inside) so that the cursor advanced
// two slots per step, and every other slot went unread.
bool mfrNext(inout uint cursor, out MfrFragment f) {
  uint c = cursor;
  uvec2 e = uvec2(0u, KB_EMPTY);
  bool found = false;
  while (!found && c < gResolveK) {  // bounded by k
    e = kbEntries[gResolveBase + c * gResolveStride];
    c += 1u;
    found = e.y != KB_EMPTY;
  }
  cursor = c;
  f = mfrUnpack(e);
  return found;
}

#include "common/resolve.glsl"
