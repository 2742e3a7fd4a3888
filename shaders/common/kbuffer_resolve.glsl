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

bool mfrNext(inout uint cursor, out MfrFragment f) {
  for (; cursor < gResolveK; ++cursor) {  // bounded by k
    uvec2 e = kbEntries[gResolveBase + cursor * gResolveStride];
    if (e.y != KB_EMPTY) {
      f = mfrUnpack(e);
      ++cursor;
      return true;
    }
  }
  return false;
}

#include "common/resolve.glsl"
