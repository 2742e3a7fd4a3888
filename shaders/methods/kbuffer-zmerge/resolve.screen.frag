// k-buffer with z-thickness fragment merging (Kim & Kye, "Z-Thickness Blending: Effective Fragment
// Merging for Multi-Fragment Rendering", Computer Graphics Forum 40(7) 2021): resolve pass. The
// pixel's stored segments (possibly overlapping, of different lengths) are one medium, piecewise
// constant between segment ends: integrated exactly front to back (Beer–Lambert per interval,
// the σ-weighted colour), then the background — the model of the operation "zthickness"
// (shaders/ops/zthickness.glsl), which it equals while no segment was merged.
#define ZM_READONLY
#include "methods/kbuffer-zmerge/segments.glsl"

uniform vec3 uBackground;
layout(location = 0) out vec4 outColor;

void main() {
  uint pixel = zmPixel(ivec2(gl_FragCoord.xy));
  float front[MFR_ZMERGE_MAX_K], back[MFR_ZMERGE_MAX_K], sigma[MFR_ZMERGE_MAX_K];
  vec3 emission[MFR_ZMERGE_MAX_K];
  uint n = 0u;
  float position = 3.4e38;
  for (uint i = 0u; i < min(uZmK, uint(MFR_ZMERGE_MAX_K)); ++i) {
    if (zmEmpty(zmSlot(pixel, i))) break;
    Segment s = zmLoad(zmSlot(pixel, i));
    front[n] = s.front;
    back[n] = s.back;
    sigma[n] = s.opticalDepth / max(s.back - s.front, 1e-30);
    emission[n] = sigma[n] * s.color;
    position = min(position, s.front);
    ++n;
  }
  vec3 color = vec3(0.0);
  float transmittance = 1.0;
  // Each step ends at the next segment front or back after `position`: at most 2n steps.
  for (uint step = 0u; step < 2u * n; ++step) {
    float next = 3.4e38;
    float extinction = 0.0;
    vec3 light = vec3(0.0);
    for (uint i = 0u; i < n; ++i) {
      if (front[i] > position) next = min(next, front[i]);
      if (back[i] > position) next = min(next, back[i]);
      if (front[i] <= position && back[i] > position) {
        extinction += sigma[i];
        light += emission[i];
      }
    }
    if (next >= 3.4e38) break;
    if (extinction > 0.0) {
      float absorbed = 1.0 - exp(-extinction * (next - position));
      color += transmittance * absorbed * (light / extinction);
      transmittance *= 1.0 - absorbed;
    }
    position = next;
  }
  outColor = vec4(color + transmittance * uBackground, 1.0);
}
