// Operation "zthickness": z-thickness blending of each pixel's sorted list — Kim & Kye, "Z-Thickness
// Blending: Effective Fragment Merging for Multi-Fragment Rendering", Computer Graphics Forum 40(7)
// 2021. Every fragment is a slab of thickness uZThickness (world units along the view z axis)
// behind its surface, whose opacity is spread over the slab: extinction σ = -ln(1 - α)/τ, emission
// σ·c. Where slabs overlap (intersecting or coplanar surfaces) they blend order-independently, with
// weights σ; slabs further apart than τ composite exactly like "over". The integral over the
// piecewise-constant medium is evaluated exactly (Beer–Lambert per interval between slab ends).
// Same arithmetic, in the same order, as the oracle's compositeZThickness
// (mfrcore/src/reference/composite.cpp).
uniform vec3 uBackground;
#include "common/eye_depth.glsl"
uniform float uZThickness;  // τ > 0, world units

struct OpState {
  vec3 color;
  float transmittance;
  float position;  // eye depth integrated up to
  uint first;      // window: open slabs, oldest at first, ends ascending (equal thickness)
  uint count;
};

// Window of open slabs (ends ascending since the fragments arrive sorted and τ is uniform).
float gSlabEnd[MFR_ZTHICK_WINDOW];
float gSlabSigma[MFR_ZTHICK_WINDOW];
vec3 gSlabEmission[MFR_ZTHICK_WINDOW];

void opBegin(inout OpState s, ivec2 pixel) {
  s.color = vec3(0.0);
  s.transmittance = 1.0;
  s.position = 0.0;
  s.first = 0u;
  s.count = 0u;
}

// Integrates the open slabs from s.position to z.
void zthickIntegrate(inout OpState s, float z) {
  if (z <= s.position) return;
  float sigma = 0.0;
  vec3 emission = vec3(0.0);
  for (uint i = 0u; i < s.count; ++i) {
    uint j = (s.first + i) % uint(MFR_ZTHICK_WINDOW);
    sigma += gSlabSigma[j];
    emission += gSlabEmission[j];
  }
  if (sigma > 0.0) {
    float absorbed = 1.0 - exp(-sigma * (z - s.position));
    s.color += s.transmittance * absorbed * (emission / sigma);
    s.transmittance *= 1.0 - absorbed;
  }
  s.position = z;
}

// Closes every open slab that ends at or before z.
void zthickCloseUntil(inout OpState s, float z) {
  for (uint i = 0u; i < uint(MFR_ZTHICK_WINDOW) && s.count > 0u && gSlabEnd[s.first] <= z; ++i) {
    zthickIntegrate(s, gSlabEnd[s.first]);
    s.first = (s.first + 1u) % uint(MFR_ZTHICK_WINDOW);
    --s.count;
  }
}

void opFragment(inout OpState s, MfrFragment f, uint position) {
  vec4 c = unpackUnorm4x8(f.color);
  float alpha = min(c.a, float(MFR_ZTHICK_MAX_ALPHA));
  if (alpha <= 0.0) return;
  float z = mfrEyeDepth(f.depth);
  zthickCloseUntil(s, z);
  if (s.count == 0u) s.position = z;  // nothing open: the medium is empty up to z
  zthickIntegrate(s, z);
  float sigma = -log(1.0 - alpha) / uZThickness;
  if (s.count == uint(MFR_ZTHICK_WINDOW)) {
    // Window full: merge into the newest open slab (its end is within τ of this one's).
    uint newest = (s.first + s.count - 1u) % uint(MFR_ZTHICK_WINDOW);
    gSlabSigma[newest] += sigma;
    gSlabEmission[newest] += sigma * vec3(c);
    return;
  }
  uint slot = (s.first + s.count) % uint(MFR_ZTHICK_WINDOW);
  gSlabEnd[slot] = z + uZThickness;
  gSlabSigma[slot] = sigma;
  gSlabEmission[slot] = sigma * vec3(c);
  ++s.count;
}

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) {
  zthickCloseUntil(s, 3.4e38);
  return vec4(s.color + s.transmittance * uBackground, 1.0);
}
