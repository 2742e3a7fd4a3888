// Operation "volume": scalar volumes composited exactly with each pixel's sorted surface fragments
// — the hybrid volume/polygon rendering of Kainz, Grabner, Bornik, Hauswiesner, Muehl, Schmalstieg,
// "Ray Casting of Multiple Volumetric Datasets with Polyhedral Boundaries on Manycore GPUs", ACM
// TOG 28(5) (SIGGRAPH Asia) 2009: the fragments sorted along the ray split it into intervals, the
// emission-absorption integral (Max, "Optical Models for Direct Volume Rendering", IEEE TVCG 1(2)
// 1995) is ray-marched over each interval, and each surface is composited with "over" at its exact
// depth — not at the nearest sample — so surfaces inside the medium are hidden by just the medium
// in front of them. Steps lie on a grid of uVolumeStep from the ray's entry into the volume's box;
// an interval cut by a surface is integrated in two parts, each with its midpoint's sample. Up to
// MFR_MAX_VOLUMES volumes are marched together (the paper's multiple volumes), the intervals also
// cut where the ray enters or leaves a box; where boxes overlap, the media mix as emission-absorption
// media do (Max 1995): extinctions add, and the emitted colour is weighted by extinction. A shaded volume scales each sample's emission by its
// gradient lighting (volumeShade).
// Same definition and float arithmetic as the oracle's compositeVolume
// (mfrcore/src/reference/composite.cpp).
uniform vec3 uBackground;
uniform mat4 uInvViewProj;   // NDC → world
uniform vec2 uViewport;      // width, height of the resolve
uniform float uVolumeStep;   // world units along the ray
uniform int uVolumeCount;    // volumes drawn, 1 … MFR_MAX_VOLUMES
uniform mat4 uWorldToGrid[MFR_MAX_VOLUMES];  // world → grid coordinates (point (i,j,k) at (i,j,k))
uniform ivec3 uGridDims[MFR_MAX_VOLUMES];
uniform float uTfLow[MFR_MAX_VOLUMES];       // scalar of the first transfer-table entry
uniform float uTfHigh[MFR_MAX_VOLUMES];      // scalar of the last one
uniform int uVolumeShading[MFR_MAX_VOLUMES]; // Volume::shading
uniform int uClip;           // Scene::clipBox: the march stays inside [uClipMin, uClipMax] too (world)
uniform vec3 uClipMin;
uniform vec3 uClipMax;
uniform int uSection;         // Scene::section: the march stays where dot(plane.xyz, p) + plane.w >= 0 (world)
uniform vec4 uSectionPlane;
// Volume i on units MFR_TEX_VOLUME + i (R32F, read with texelFetch) and MFR_TEX_VOLUME_TF + i
// ((rgb, σ), MFR_VOLUME_TF_SIZE entries); indexed only by loop counters bounded by a uniform, so
// dynamically uniform as GLSL 4.50 requires.
layout(binding = MFR_TEX_VOLUME) uniform sampler3D uVolume[MFR_MAX_VOLUMES];
layout(binding = MFR_TEX_VOLUME_TF) uniform sampler1D uTransfer[MFR_MAX_VOLUMES];
#include "common/volume_sample.glsl"

struct OpState {
  vec3 color;
  float transmittance;
  vec3 rayStart;  // world point of the pixel's centre on the near plane
  vec3 rayDir;    // unit
  vec2 ndc;
  vec3 gridStart[MFR_MAX_VOLUMES];  // the ray in volume i's grid coordinates: gridStart + t·gridDir
  vec3 gridDir[MFR_MAX_VOLUMES];
  float enter[MFR_MAX_VOLUMES];     // volume i's part of the ray (empty: enter == exit)
  float exit[MFR_MAX_VOLUMES];
  float tEnter, tExit, step;  // from the first entry into a box to the last exit, and the step used
  float t;                    // integrated up to
  int next;                   // index of the next step boundary tEnter + next·step
};

// Trilinear interpolation, clamped to the grid (VolumeGrid::sample).
float volumeSample(int v, vec3 g) { return mfrTrilinear(uVolume[v], uGridDims[v], g); }

// (rgb, σ) of a scalar: volume v's table interpolated linearly (TransferFunction::table).
// a / b with both scaled by 2^-32 (exactly) where |b| > 2^100: GLSL's division is accurate only for
// divisors up to 2^126, and a reciprocal of a larger one may flush to 0 (VolumeMarcher::divide).
float volumeDivide(float a, float b) {
  precise float s = abs(b) > 1.2676506002282294e30 ? 2.3283064365386963e-10 : 1.0;
  precise float q = (a * s) / (b * s);
  return q;
}

// Halved first, exactly (`precise`: not folded back): value − low overflows a float beyond
// ±1.7e38; NaN (a table of one value) is the first entry.
vec4 volumeTransfer(int v, float value) {
  precise float along = volumeDivide(0.5 * value - 0.5 * uTfLow[v], 0.5 * uTfHigh[v] - 0.5 * uTfLow[v]);
  float u = (along > 0.0 ? min(along, 1.0) : 0.0) * float(MFR_VOLUME_TF_SIZE - 1);
  int i = min(int(u), MFR_VOLUME_TF_SIZE - 2);
  float f = u - float(i);
  return mix(texelFetch(uTransfer[v], i, 0), texelFetch(uTransfer[v], i + 1, 0), f);
}

// The emission factor of a shaded volume at grid point g (MFR_VOLUME_AMBIENT in common/bindings.h;
// Levoy 1988): headlight diffuse on the normalised world gradient, faded out where the gradient
// is small against the transfer function's range.
float volumeHalfDifference(int v, vec3 g, vec3 d) {
  precise float difference = 0.5 * volumeSample(v, g + d) - 0.5 * volumeSample(v, g - d);
  return difference;
}

// Central differences halved before subtracting and measured in units of the largest component:
// no step overflows a float (VolumeMarcher::shade, the same steps).
float volumeShade(int v, vec3 g, vec3 rayDir) {
  vec3 gradient = vec3(volumeHalfDifference(v, g, vec3(1.0, 0.0, 0.0)), volumeHalfDifference(v, g, vec3(0.0, 1.0, 0.0)),
                       volumeHalfDifference(v, g, vec3(0.0, 0.0, 1.0)));
  float largest = max(max(abs(gradient.x), abs(gradient.y)), abs(gradient.z));
  if (!(largest > 0.0)) return 1.0;
  vec3 unit = vec3(volumeDivide(gradient.x, largest), volumeDivide(gradient.y, largest),
                   volumeDivide(gradient.z, largest));
  float perCell = length(unit);
  vec3 world = transpose(mat3(uWorldToGrid[v])) * unit;
  float facing = abs(dot(world, rayDir)) / length(world);
  float lit = float(MFR_VOLUME_AMBIENT) + float(MFR_VOLUME_DIFFUSE) * facing;
  precise float range = 2.0 * volumeDivide(0.5 * uTfHigh[v] - 0.5 * uTfLow[v], largest);
  float w = perCell / (perCell + float(MFR_VOLUME_SHADE_EDGE) * range);
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
  // The part of the ray every volume shares: inside the clip box and on the kept side of the plane.
  float c0 = 0.0, c1 = rayLength;
  if (uClip != 0) {  // slabs of the clip box, in world space
    for (int a = 0; a < 3; ++a) {
      if (abs(s.rayDir[a]) < 1e-30) {
        if (s.rayStart[a] < uClipMin[a] || s.rayStart[a] > uClipMax[a]) c1 = -1.0;
      } else {
        float ta = (uClipMin[a] - s.rayStart[a]) / s.rayDir[a];
        float tb = (uClipMax[a] - s.rayStart[a]) / s.rayDir[a];
        c0 = max(c0, min(ta, tb));
        c1 = min(c1, max(ta, tb));
      }
    }
  }
  if (uSection != 0) {  // the kept half-space of the section plane
    float s0 = dot(uSectionPlane.xyz, s.rayStart) + uSectionPlane.w, ds = dot(uSectionPlane.xyz, s.rayDir);
    if (abs(ds) < 1e-30) {
      if (s0 < 0.0) c1 = -1.0;
    } else if (ds > 0.0) {
      c0 = max(c0, -s0 / ds);
    } else {
      c1 = min(c1, -s0 / ds);
    }
  }
  bool any = false;
  s.tEnter = 0.0;
  s.tExit = 0.0;
  for (int v = 0; v < MFR_MAX_VOLUMES; ++v) {
    s.enter[v] = 0.0;
    s.exit[v] = 0.0;
    if (v >= uVolumeCount) continue;
    s.gridStart[v] = (uWorldToGrid[v] * vec4(s.rayStart, 1.0)).xyz;
    s.gridDir[v] = (uWorldToGrid[v] * vec4(s.rayDir, 0.0)).xyz;
    float t0 = c0, t1 = c1;
    vec3 last = vec3(uGridDims[v] - 1);
    for (int a = 0; a < 3; ++a) {  // slabs of the box [0, dims - 1]
      if (abs(s.gridDir[v][a]) < 1e-30) {
        if (s.gridStart[v][a] < 0.0 || s.gridStart[v][a] > last[a]) t1 = -1.0;
      } else {
        float ta = (0.0 - s.gridStart[v][a]) / s.gridDir[v][a];
        float tb = (last[a] - s.gridStart[v][a]) / s.gridDir[v][a];
        t0 = max(t0, min(ta, tb));
        t1 = min(t1, max(ta, tb));
      }
    }
    s.enter[v] = t0;
    s.exit[v] = max(t1, t0);
    if (s.exit[v] > s.enter[v]) {
      s.tEnter = any ? min(s.tEnter, s.enter[v]) : s.enter[v];
      s.tExit = any ? max(s.tExit, s.exit[v]) : s.exit[v];
      any = true;
    }
  }
  if (!any) {
    s.tEnter = c0 > 0.0 ? c0 : 0.0;
    s.tExit = s.tEnter;
  }
  s.step = max(uVolumeStep, (s.tExit - s.tEnter) / float(MFR_VOLUME_MAX_STEPS));
  s.t = s.tEnter;
  s.next = 1;
}

// Integrates the media from s.t to tTo (clipped to the boxes), one midpoint sample per interval.
void volumeMarch(inout OpState s, float tTo) {
  tTo = min(tTo, s.tExit);
  for (int it = 0; it < MFR_VOLUME_MAX_STEPS + 2 + 2 * MFR_MAX_VOLUMES && s.t < tTo &&
                  s.transmittance >= float(MFR_VOLUME_MIN_TRANSMITTANCE);
       ++it) {
    float boundary = s.tEnter + float(s.next) * s.step;
    float end = min(boundary, tTo);
    for (int v = 0; v < MFR_MAX_VOLUMES; ++v) {  // a box's entry or exit cuts the interval too
      if (v >= uVolumeCount) break;
      if (s.enter[v] > s.t && s.enter[v] < end) end = s.enter[v];
      if (s.exit[v] > s.t && s.exit[v] < end) end = s.exit[v];
    }
    if (end > s.t) {
      float mid = 0.5 * (s.t + end);
      float sigma = 0.0;
      vec3 emission = vec3(0.0);
      for (int v = 0; v < MFR_MAX_VOLUMES; ++v) {
        if (v >= uVolumeCount) break;
        if (!(mid > s.enter[v] && mid < s.exit[v])) continue;
        vec3 g = s.gridStart[v] + s.gridDir[v] * mid;
        vec4 m = volumeTransfer(v, volumeSample(v, g));
        if (m.a > 0.0) {
          sigma += m.a;
          emission += m.a * m.rgb * (uVolumeShading[v] != 0 ? volumeShade(v, g, s.rayDir) : 1.0);
        }
      }
      if (sigma > 0.0) {
        float absorbed = 1.0 - exp(-sigma * (end - s.t));
        s.color += s.transmittance * absorbed * (emission / sigma);
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
