// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] Inputs of every capture fragment shader (*.geom.frag) and the shaded payload of the current
// fragment. The colour comes from common/shading.h, the definition the CPU oracle uses too.
#include "common/bindings.h"
#include "common/shading.h"
#include "common/payload.glsl"

in vec3 vNormal;
in vec4 vColor;
uniform vec3 uViewDir;
uniform uint uObjectId;

vec4 mfrShadedColor() { return mfrShade(vColor, vNormal, uViewDir); }

MfrFragment mfrCurrentFragment() { return MfrFragment(packUnorm4x8(mfrShadedColor()), gl_FragCoord.z); }
