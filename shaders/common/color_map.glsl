// [Colour mapping of scalar fields on surfaces, as in ParaView's "Color by" — Moreland, "Diverging
// Color Maps for Scientific Visualization", ISVC 2009 (the default map, cool-warm).] The colour of a
// field value: the value is interpolated across the triangle first, then mapped (ParaView's
// "interpolate scalars before mapping"), so a triangle spanning the range shows every colour in
// between. The same arithmetic as mfr::mapFieldValue (scene/color_map.cpp), which the oracle uses.
#include "common/bindings.h"

layout(binding = MFR_TEX_COLOR_MAPS) uniform sampler2D uColorMaps;
uniform int uColorMapRow;     // the map's row in uColorMaps; negative: the surface is not field-coloured
uniform vec2 uColorMapRange;  // the values mapped to the map's ends

vec3 mfrMapFieldValue(float value) {
  if (isnan(value)) return texelFetch(uColorMaps, ivec2(MFR_COLOR_MAP_SIZE, uColorMapRow), 0).rgb;
  float span = uColorMapRange.y - uColorMapRange.x;
  float t = span > 0.0 ? clamp((value - uColorMapRange.x) / span, 0.0, 1.0) : 0.5;
  float x = t * float(MFR_COLOR_MAP_SIZE - 1);
  int i = min(int(x), MFR_COLOR_MAP_SIZE - 2);
  vec3 a = texelFetch(uColorMaps, ivec2(i, uColorMapRow), 0).rgb;
  vec3 b = texelFetch(uColorMaps, ivec2(i + 1, uColorMapRow), 0).rgb;
  return mix(a, b, x - float(i));
}
