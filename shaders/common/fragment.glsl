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

vec4 mfrShadedColor() {
  // A field-coloured surface: the map's colour, the material's opacity (vColor.a is uColor.a then).
  vec4 base = uColorMapRow >= 0 ? vec4(mfrMapFieldValue(mfrFieldValue()), vColor.a) : vColor;
  return mfrShade(base, vNormal, uViewDir);
}

MfrFragment mfrCurrentFragment() {
  uint word = uPayload == MFR_PAYLOAD_OBJECT ? uObjectId * 2u + (gl_FrontFacing ? 1u : 0u)
                                             : packUnorm4x8(mfrShadedColor());
  return MfrFragment(word, gl_FragCoord.z);
}
