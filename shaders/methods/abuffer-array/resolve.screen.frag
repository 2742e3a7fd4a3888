// A-buffer with fixed-size per-pixel arrays (FreePipe, Liu et al., I3D 2010; Crassin 2010):
// resolve pass. Reads the pixel's min(count, uSlots) stored slots and hands them to the shared
// gather/sort/operate driver.
#include "methods/abuffer-array/array.glsl"

layout(r32ui, binding = MFR_IMAGE_COUNTS) uniform readonly uimage2D uCounts;

uint gPixel;  // pixel index of the list being walked
uint gEnd;    // stored fragments of that pixel

uint mfrCursorBegin(ivec2 pixel) {
  gPixel = pixelIndex(pixel);
  gEnd = min(imageLoad(uCounts, pixel).x, uSlots);
  return 0u;
}

bool mfrNext(inout uint cursor, out MfrFragment f) {
  if (cursor >= gEnd) return false;
  f = mfrUnpack(arrayFragments[cursor * uPixels + gPixel]);
  ++cursor;
  return true;
}

#include "common/resolve.glsl"
