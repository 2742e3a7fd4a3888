// Operation "oit": front-to-back "over" compositing with the background (Porter & Duff 1984;
// as in every OIT paper, e.g. Yang et al. 2010).
#include "ops/over_core.glsl"

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) { return vec4(s.color + s.transmittance * uBackground, 1.0); }
