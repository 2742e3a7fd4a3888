// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] Headlight shading shared verbatim by GLSL shaders and the C++ oracle (one definition; see
// docs/architecture.md, "The shading function"). It must stay valid GLSL 4.50 and valid C++ with
// GLM: no swizzles, float literals with an f suffix, only functions both languages have.
// Model: a directional light along the view direction, two-sided Lambert plus ambient, straight
// (not premultiplied) colour; opacity passes through unchanged.
#ifndef MFR_SHADING_H
#define MFR_SHADING_H

const float MFR_AMBIENT = 0.3f;

vec4 mfrShade(vec4 baseColor, vec3 normal, vec3 viewDir) {
  // |n·l|: a transparent surface is seen from both sides, so back faces are lit like front faces.
  float lambert = abs(dot(normalize(normal), viewDir));
  float light = MFR_AMBIENT + (1.0f - MFR_AMBIENT) * lambert;
  return vec4(vec3(baseColor) * light, baseColor.a);
}

#endif
