// S-buffer (Vasilakis & Fudos, EG 2012 short papers): resolve pass. The pixel's fragments are the
// contiguous range offsets[p] … offsets[p] + n, n = arrivals of the store pass clipped to the
// pixel's counted range and to the buffer; the shared driver gathers, sorts and operates.
#include "methods/abuffer-sbuffer/sbuffer.glsl"

uint gEnd;  // end of the pixel's stored range

uint mfrCursorBegin(ivec2 pixel) {
  uint p = pixelIndex(pixel);
  uint begin = sOffsets[p];
  uint end = min(sOffsets[p + 1u], uCapacity);
  gEnd = end > begin ? min(end, begin + sCounts[p]) : begin;
  return begin;
}

bool mfrNext(inout uint cursor, out MfrFragment f) {
  if (cursor >= gEnd) return false;
  f = mfrUnpack(sFragments[cursor]);
  ++cursor;
  return true;
}

#include "common/resolve.glsl"
