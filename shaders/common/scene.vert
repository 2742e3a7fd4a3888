// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] Scene vertex shader shared by every capture pass: world-space normal, material × vertex colour
// (the material's alone when uVertexColors is 0), the field value a surface may be coloured by (or its point in the volume that colours it), object id. Multifragment capture itself happens in each method's *.geom.frag.
#include "common/bindings.h"

layout(location = MFR_ATTR_POSITION) in vec3 aPosition;
layout(location = MFR_ATTR_NORMAL) in vec3 aNormal;
layout(location = MFR_ATTR_COLOR) in vec4 aColor;
layout(location = MFR_ATTR_SCALAR) in float aScalar;

uniform mat4 uViewProj;
uniform mat4 uModel;
uniform mat3 uNormalMatrix;
uniform vec4 uColor;
uniform int uVertexColors;  // 0: the object's colour replaces the mesh's per-vertex colours
uniform vec2 uColorMapRange;  // common/color_map.glsl: the field's values at the map's ends
// A surface coloured by a volume: object → that volume's grid coordinates (common/fragment.glsl
// samples it per fragment at vFieldGrid; affine, so interpolating it is exact).
uniform mat4 uFieldToGrid;
// Scene::clipBox: distances to its six faces, positive inside. uModel, uViewProj and the box are
// relative to a point of the view axis (gl::FrameUniforms::origin), so that far scenes and small parts keep float precision. GL clips with them
// only while GpuScene::draw enables GL_CLIP_DISTANCE0…5 (a scene with a clip box).
uniform vec3 uClipMin;
uniform vec3 uClipMax;
out float gl_ClipDistance[6];

out vec3 vNormal;
out vec4 vColor;
out float vScalar;  // mapped per fragment (common/color_map.glsl), after interpolation
out vec3 vFieldGrid;
// Multi-pass methods compare a fragment's depth across programs (peeling, the nearest and
// farthest passes, the tail runs): GLSL guarantees equal positions across programs only for an
// invariant output.
invariant gl_Position;

void main() {
  vNormal = uNormalMatrix * aNormal;
  vColor = uVertexColors != 0 ? uColor * aColor : uColor;
  // Bounded before interpolation (MFR_COLOR_MAP_BAND), as mfr::boundFieldValue does; NaN stays NaN.
  float band = float(MFR_COLOR_MAP_BAND) * (uColorMapRange.y - uColorMapRange.x);
  vScalar = isnan(aScalar) ? aScalar : clamp(aScalar, uColorMapRange.x - band, uColorMapRange.y + band);
  vFieldGrid = (uFieldToGrid * vec4(aPosition, 1.0)).xyz;
  vec4 world = uModel * vec4(aPosition, 1.0);
  gl_Position = uViewProj * world;
  vec3 below = world.xyz - uClipMin, above = uClipMax - world.xyz;
  gl_ClipDistance[0] = below.x;
  gl_ClipDistance[1] = below.y;
  gl_ClipDistance[2] = below.z;
  gl_ClipDistance[3] = above.x;
  gl_ClipDistance[4] = above.y;
  gl_ClipDistance[5] = above.z;
}
