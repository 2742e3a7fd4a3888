// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] Inputs of every capture fragment shader (*.geom.frag) and the shaded payload of the current
// fragment. The colour comes from common/shading.h, the definition the CPU oracle uses too.
#include "common/bindings.h"
#include "common/shading.h"
#include "common/payload.glsl"
#include "common/color_map.glsl"

in vec3 vNormal;
in vec4 vColor;
in float vScalar;
in vec3 vFieldGrid;
uniform vec3 uViewDir;
uniform uint uObjectId;
// MFR_PAYLOAD_COLOR: the shaded colour; MFR_PAYLOAD_OBJECT: objectId·2 + frontFacing in the colour
// word (operations that classify fragments by object, such as "csg", need that, not the colour).
uniform int uPayload;

// A surface coloured by a volume ("@NAME", mfr::VolumeFieldSampler): 1, and that volume's grid on
// MFR_TEX_FIELD_GRID; its value is sampled at each fragment, not interpolated from the vertices.
uniform int uFieldGrid;
uniform ivec3 uFieldGridDims;
layout(binding = MFR_TEX_FIELD_GRID) uniform sampler3D uFieldGridSamples;
#include "common/volume_sample.glsl"

// The field value the colour map maps: the vertices' interpolated, or the volume's here — NaN
// farther than half a voxel outside its box, else bounded as scene.vert bounds a vertex's.
float mfrFieldValue() {
  if (uFieldGrid == 0) return vScalar;
  vec3 last = vec3(uFieldGridDims - 1);
  if (any(lessThan(vFieldGrid, vec3(-0.5))) || any(greaterThan(vFieldGrid, last + 0.5))) return uintBitsToFloat(0x7fc00000u);
  float value = mfrTrilinear(uFieldGridSamples, uFieldGridDims, vFieldGrid);
  float band = float(MFR_COLOR_MAP_BAND) * (uColorMapRange.y - uColorMapRange.x);
  return isnan(value) ? value : clamp(value, uColorMapRange.x - band, uColorMapRange.y + band);
}

// The material's colour, and whether the mesh's vertex colours multiply it (then in vColor).
uniform vec4 uColor;
uniform int uVertexColors;

vec4 mfrShadedColor() {
  // One colour per object is read from the uniform, not interpolated: perspective interpolation
  // of a constant can move it by an ulp, which flips a colour on an 8-bit rounding tie (0.3·255 =
  // 76.5) on some fragments only, so that one part's faces no longer match each other or the
  // oracle's, which uses the material's colour as it is.
  vec4 material = uVertexColors != 0 ? vColor : uColor;
  // A field-coloured surface: the map's colour, the material's opacity.
  vec4 base = uColorMapRow >= 0 ? vec4(mfrMapFieldValue(mfrFieldValue()), uColor.a) : material;
  return mfrShade(base, vNormal, uViewDir);
}

MfrFragment mfrCurrentFragment() {
  uint word = uPayload == MFR_PAYLOAD_OBJECT ? uObjectId * 2u + (gl_FrontFacing ? 1u : 0u)
                                             : packUnorm4x8(mfrShadedColor());
  return MfrFragment(word, gl_FragCoord.z);
}
