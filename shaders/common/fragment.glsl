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
uniform vec3 uViewDir;
uniform uint uObjectId;
// MFR_PAYLOAD_COLOR: the shaded colour; MFR_PAYLOAD_OBJECT: objectId·2 + frontFacing in the colour
// word (operations that classify fragments by object, such as "csg", need that, not the colour).
uniform int uPayload;

vec4 mfrShadedColor() {
  // A field-coloured surface: the map's colour, the material's opacity (vColor.a is uColor.a then).
  vec4 base = uColorMapRow >= 0 ? vec4(mfrMapFieldValue(vScalar), vColor.a) : vColor;
  return mfrShade(base, vNormal, uViewDir);
}

MfrFragment mfrCurrentFragment() {
  uint word = uPayload == MFR_PAYLOAD_OBJECT ? uObjectId * 2u + (gl_FrontFacing ? 1u : 0u)
                                             : packUnorm4x8(mfrShadedColor());
  return MfrFragment(word, gl_FragCoord.z);
}
