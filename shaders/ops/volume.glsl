// Operation "volume": a scalar volume composited exactly with each pixel's sorted surface fragments
// — the hybrid volume/polygon rendering of Kainz, Grabner, Bornik, Hauswiesner, Muehl, Schmalstieg,
// "Ray Casting of Multiple Volumetric Datasets with Polyhedral Boundaries on Manycore GPUs", ACM
// TOG 28(5) (SIGGRAPH Asia) 2009: the fragments sorted along the ray split it into intervals, the
// emission-absorption integral (Max, "Optical Models for Direct Volume Rendering", IEEE TVCG 1(2)
// 1995) is ray-marched over each interval, and each surface is composited with "over" at its exact
// depth — not at the nearest sample — so surfaces inside the medium are hidden by just the medium
// in front of them. Steps lie on a grid of uVolumeStep from the ray's entry into the volume's box;
// an interval cut by a surface is integrated in two parts, each with its midpoint's sample. A
// shaded volume scales each sample's emission by its gradient lighting (volumeShade).
// Same definition and float arithmetic as the oracle's compositeVolume
// (mfrcore/src/reference/composite.cpp).
uniform vec3 uBackground;
uniform mat4 uInvViewProj;   // NDC → world
uniform vec2 uViewport;      // width, height of the resolve
uniform mat4 uWorldToGrid;   // world → grid coordinates (point (i,j,k) at (i,j,k))
uniform ivec3 uGridDims;
uniform float uVolumeStep;   // world units along the ray
uniform float uTfLow;        // scalar of the first transfer-table entry
uniform float uTfHigh;       // scalar of the last one
uniform int uVolumeShading;  // Volume::shading
uniform int uClip;           // Scene::clipBox: the march stays inside [uClipMin, uClipMax] too (world)
uniform vec3 uClipMin;
uniform vec3 uClipMax;
uniform int uSection;         // Scene::section: the march stays where dot(plane.xyz, p) + plane.w >= 0 (world)
uniform vec4 uSectionPlane;
layout(binding = MFR_TEX_VOLUME) uniform sampler3D uVolume;       // R32F, read with texelFetch
layout(binding = MFR_TEX_VOLUME_TF) uniform sampler1D uTransfer;  // (rgb, σ), MFR_VOLUME_TF_SIZE

struct OpState {
  vec3 color;
  float transmittance;
  vec3 rayStart;  // world point of the pixel's centre on the near plane
  vec3 rayDir;    // unit
  vec2 ndc;
  vec3 gridStart;  // the ray in grid coordinates: gridStart + t·gridDir, t in world units
  vec3 gridDir;
  float tEnter, tExit, step;  // the part of the ray inside the box, and the step used
  float t;                    // integrated up to
  int next;                   // index of the next step boundary tEnter + next·step
};

// Trilinear interpolation, clamped to the grid (VolumeGrid::sample).
float volumeSample(vec3 g) {
  vec3 last = vec3(uGridDims - 1);
  vec3 c = clamp(g, vec3(0.0), last);
  ivec3 i0 = min(ivec3(floor(c)), uGridDims - 2);
  vec3 f = c - vec3(i0);
  float v000 = texelFetch(uVolume, i0, 0).r;
  float v100 = texelFetch(uVolume, i0 + ivec3(1, 0, 0), 0).r;
  float v010 = texelFetch(uVolume, i0 + ivec3(0, 1, 0), 0).r;
  float v110 = texelFetch(uVolume, i0 + ivec3(1, 1, 0), 0).r;
  float v001 = texelFetch(uVolume, i0 + ivec3(0, 0, 1), 0).r;
  float v101 = texelFetch(uVolume, i0 + ivec3(1, 0, 1), 0).r;
  float v011 = texelFetch(uVolume, i0 + ivec3(0, 1, 1), 0).r;
  float v111 = texelFetch(uVolume, i0 + ivec3(1, 1, 1), 0).r;
  float x00 = mix(v000, v100, f.x);
  float x10 = mix(v010, v110, f.x);
  float x01 = mix(v001, v101, f.x);
  float x11 = mix(v011, v111, f.x);
  return mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
}

// (rgb, σ) of a scalar: the table interpolated linearly (TransferFunction::table).
vec4 volumeTransfer(float v) {
  float u = clamp((v - uTfLow) / (uTfHigh - uTfLow), 0.0, 1.0) * float(MFR_VOLUME_TF_SIZE - 1);
  int i = min(int(u), MFR_VOLUME_TF_SIZE - 2);
  float f = u - float(i);
  return mix(texelFetch(uTransfer, i, 0), texelFetch(uTransfer, i + 1, 0), f);
}

// The emission factor of a shaded volume at grid point g (MFR_VOLUME_AMBIENT in common/bindings.h;
// Levoy 1988): headlight diffuse on the normalised world gradient, faded out where the gradient
// is small against the transfer function's range.
float volumeShade(vec3 g, vec3 rayDir) {
  vec3 gradient = 0.5 * vec3(volumeSample(g + vec3(1.0, 0.0, 0.0)) - volumeSample(g - vec3(1.0, 0.0, 0.0)),
                             volumeSample(g + vec3(0.0, 1.0, 0.0)) - volumeSample(g - vec3(0.0, 1.0, 0.0)),
                             volumeSample(g + vec3(0.0, 0.0, 1.0)) - volumeSample(g - vec3(0.0, 0.0, 1.0)));
  float perCell = length(gradient);
  if (!(perCell > 0.0)) return 1.0;
  vec3 world = transpose(mat3(uWorldToGrid)) * gradient;
  float facing = abs(dot(world, rayDir)) / length(world);
  float lit = float(MFR_VOLUME_AMBIENT) + float(MFR_VOLUME_DIFFUSE) * facing;
  float w = perCell / (perCell + float(MFR_VOLUME_SHADE_EDGE) * (uTfHigh - uTfLow));
  return mix(1.0, lit, w);
}

vec3 volumeUnproject(vec2 ndc, float ndcZ) {
  vec4 p = uInvViewProj * vec4(ndc, ndcZ, 1.0);
  return p.xyz / p.w;
}

void opBegin(inout OpState s, ivec2 pixel) {
  s.color = vec3(0.0);
  s.transmittance = 1.0;
  s.ndc = (vec2(pixel) + 0.5) / uViewport * 2.0 - 1.0;
  s.rayStart = volumeUnproject(s.ndc, -1.0);
  vec3 rayEnd = volumeUnproject(s.ndc, 1.0);
  float rayLength = distance(rayEnd, s.rayStart);
  s.rayDir = (rayEnd - s.rayStart) / rayLength;
  s.gridStart = (uWorldToGrid * vec4(s.rayStart, 1.0)).xyz;
  s.gridDir = (uWorldToGrid * vec4(s.rayDir, 0.0)).xyz;
  // Slabs of the box [0, dims - 1].
  float t0 = 0.0, t1 = rayLength;
  vec3 last = vec3(uGridDims - 1);
  for (int a = 0; a < 3; ++a) {
    if (abs(s.gridDir[a]) < 1e-30) {
      if (s.gridStart[a] < 0.0 || s.gridStart[a] > last[a]) t1 = -1.0;
    } else {
      float ta = (0.0 - s.gridStart[a]) / s.gridDir[a];
      float tb = (last[a] - s.gridStart[a]) / s.gridDir[a];
      t0 = max(t0, min(ta, tb));
      t1 = min(t1, max(ta, tb));
    }
  }
  if (uClip != 0) {  // slabs of the clip box, in world space
    for (int a = 0; a < 3; ++a) {
      if (abs(s.rayDir[a]) < 1e-30) {
        if (s.rayStart[a] < uClipMin[a] || s.rayStart[a] > uClipMax[a]) t1 = -1.0;
      } else {
        float ta = (uClipMin[a] - s.rayStart[a]) / s.rayDir[a];
        float tb = (uClipMax[a] - s.rayStart[a]) / s.rayDir[a];
        t0 = max(t0, min(ta, tb));
        t1 = min(t1, max(ta, tb));
      }
    }
  }
  if (uSection != 0) {  // the kept half-space of the section plane
    float s0 = dot(uSectionPlane.xyz, s.rayStart) + uSectionPlane.w, ds = dot(uSectionPlane.xyz, s.rayDir);
    if (abs(ds) < 1e-30) {
      if (s0 < 0.0) t1 = -1.0;
    } else if (ds > 0.0) {
      t0 = max(t0, -s0 / ds);
    } else {
      t1 = min(t1, -s0 / ds);
    }
  }
  s.tEnter = t0;
  s.tExit = max(t1, t0);
  s.step = max(uVolumeStep, (s.tExit - s.tEnter) / float(MFR_VOLUME_MAX_STEPS));
  s.t = s.tEnter;
  s.next = 1;
}

// Integrates the medium from s.t to tTo (clipped to the box), one midpoint sample per interval.
void volumeMarch(inout OpState s, float tTo) {
  tTo = min(tTo, s.tExit);
  for (int it = 0; it < MFR_VOLUME_MAX_STEPS + 2 && s.t < tTo &&
                  s.transmittance >= float(MFR_VOLUME_MIN_TRANSMITTANCE);
       ++it) {
    float boundary = s.tEnter + float(s.next) * s.step;
    float end = min(boundary, tTo);
    if (end > s.t) {
      vec3 g = s.gridStart + s.gridDir * (0.5 * (s.t + end));
      vec4 m = volumeTransfer(volumeSample(g));
      if (m.a > 0.0) {
        float absorbed = 1.0 - exp(-m.a * (end - s.t));
        s.color += s.transmittance * absorbed * m.rgb * (uVolumeShading != 0 ? volumeShade(g, s.rayDir) : 1.0);
        s.transmittance *= 1.0 - absorbed;
      }
      s.t = end;
    }
    if (end >= boundary) ++s.next;
  }
}

void opFragment(inout OpState s, MfrFragment f, uint position) {
  float t = dot(volumeUnproject(s.ndc, 2.0 * f.depth - 1.0) - s.rayStart, s.rayDir);
  volumeMarch(s, t);
  vec4 c = unpackUnorm4x8(f.color);
  s.color += s.transmittance * c.a * vec3(c);
  s.transmittance *= 1.0 - c.a;
}

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) {
  volumeMarch(s, s.tExit);
  return vec4(s.color + s.transmittance * uBackground, 1.0);
}
