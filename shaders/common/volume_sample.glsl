// [Volume sampling shared by the hybrid volume/polygon compositing of Kainz et al., "Ray Casting of
// Multiple Volumetric Datasets with Polyhedral Boundaries on Manycore GPUs", ACM TOG 28(5) 2009
// (ops/volume.glsl) and by surfaces coloured by a volume (common/fragment.glsl).] Trilinear
// interpolation of a scalar grid at grid coordinates g (point (i,j,k) at (i,j,k)), clamped to the
// grid, with texelFetch and the same float arithmetic as VolumeGrid::sample on the CPU — not the
// texture unit's filtering, whose weights some GPUs round to 8 bits. The samples are halved, and
// the result doubled, exactly: mix may be compiled as a + t·(b − a), whose b − a overflows a float
// for values beyond ±1.7e38 (±FLT_MAX "no data" marks). `precise`: the compiler must not fold the
// halving back into the difference.
float mfrTrilinear(sampler3D grid, ivec3 dims, vec3 g) {
  vec3 last = vec3(dims - 1);
  vec3 c = clamp(g, vec3(0.0), last);
  ivec3 i0 = min(ivec3(floor(c)), dims - 2);
  vec3 f = c - vec3(i0);
  precise float v000 = 0.5 * texelFetch(grid, i0, 0).r;
  precise float v100 = 0.5 * texelFetch(grid, i0 + ivec3(1, 0, 0), 0).r;
  precise float v010 = 0.5 * texelFetch(grid, i0 + ivec3(0, 1, 0), 0).r;
  precise float v110 = 0.5 * texelFetch(grid, i0 + ivec3(1, 1, 0), 0).r;
  precise float v001 = 0.5 * texelFetch(grid, i0 + ivec3(0, 0, 1), 0).r;
  precise float v101 = 0.5 * texelFetch(grid, i0 + ivec3(1, 0, 1), 0).r;
  precise float v011 = 0.5 * texelFetch(grid, i0 + ivec3(0, 1, 1), 0).r;
  precise float v111 = 0.5 * texelFetch(grid, i0 + ivec3(1, 1, 1), 0).r;
  precise float x00 = mix(v000, v100, f.x);
  precise float x10 = mix(v010, v110, f.x);
  precise float x01 = mix(v001, v101, f.x);
  precise float x11 = mix(v011, v111, f.x);
  precise float halfValue = mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
  return 2.0 * halfValue;
}
