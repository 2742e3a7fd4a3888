// Operation "csg": image-space CSG on each pixel's sorted list — a ray's inside/outside
// classification against a Boolean tree of closed solids, as in image-space CSG since Goldfeather,
// Molnar, Turk, Fuchs, "Near real-time CSG rendering using tree normalization and geometric
// pruning", IEEE CG&A 9(3) 1989, done here on multifragment lists (Vasilakis, Vardis,
// Papaioannou, "A Survey of Multifragment Rendering", CGF 39(2) 2020, §6 CSG).
// The capture stored objectId·2 + frontFacing in each fragment's colour word (MFR_PAYLOAD_OBJECT).
// Same rule as the oracle's csgVisibleFragment (mfrcore/src/scene/csg.cpp): inside states start
// outside; a front face sets its primitive's bit, a back face clears it; the visible fragment is
// the first where the tree goes from outside to inside, or the first of an object not in the
// tree. This pass records it (object, depth); ops/csg_shade.geom.frag then shades it.
layout(std430, binding = MFR_SSBO_CSG) writeonly buffer CsgVisible { uvec2 csgVisible[]; };
uniform vec3 uBackground;
uniform int uCsgWidth;
uniform uint uCsgProgram[MFR_CSG_MAX_PROGRAM];  // postfix words (bindings.h)
uniform uint uCsgProgramLength;
uniform uint uCsgPrimitives[MFR_CSG_MAX_PRIMITIVES];  // object id of primitive bit i
uniform uint uCsgPrimitiveCount;
uniform uint uCsgMirrored;  // bit i: primitive i's transform mirrors, its facings are reversed

struct OpState {
  uint mask;     // bit i: inside primitive i
  bool found;
  uint object;
  float depth;
};

bool csgInside(uint mask) {
  uint stack = 0u;  // bit stack, top at bit depth−1
  uint depth = 0u;
  for (uint i = 0u; i < min(uCsgProgramLength, uint(MFR_CSG_MAX_PROGRAM)); ++i) {
    uint word = uCsgProgram[i];
    uint op = word & 0xFFu;
    if (op == MFR_CSG_PRIMITIVE) {
      // 32 bits hold a stack 32 deep, what validateCsg allows (a clamp at 31 lost the 32nd
      // operand of a right-nested tree). Deeper never comes; the guard keeps the shift defined.
      uint bit = (mask >> ((word >> 8u) & 31u)) & 1u;
      if (depth < 32u) stack = (stack & ~(1u << depth)) | (bit << depth);
      depth = min(depth + 1u, 32u);
    } else {
      depth = max(depth, 2u) - 2u;
      bool a = ((stack >> depth) & 1u) != 0u;
      bool b = ((stack >> (depth + 1u)) & 1u) != 0u;
      bool r = op == MFR_CSG_UNION ? (a || b) : op == MFR_CSG_INTERSECTION ? (a && b) : (a && !b);
      stack = (stack & ~(1u << depth)) | ((r ? 1u : 0u) << depth);
      depth += 1u;
    }
  }
  return depth > 0u && (stack & 1u) != 0u;
}

void opBegin(inout OpState s, ivec2 pixel) {
  s.mask = 0u;
  s.found = false;
  s.object = 0u;
  s.depth = 1.0;
}

void opFragment(inout OpState s, MfrFragment f, uint position) {
  if (s.found) return;
  uint object = f.color >> 1u;
  bool front = (f.color & 1u) != 0u;
  uint bit = 32u;
  for (uint i = 0u; i < min(uCsgPrimitiveCount, uint(MFR_CSG_MAX_PRIMITIVES)); ++i)
    if (uCsgPrimitives[i] == object) {
      bit = i;
      break;
    }
  bool visible = bit == 32u;
  if (!visible) {
    bool before = csgInside(s.mask);
    bool entering = front != (((uCsgMirrored >> bit) & 1u) != 0u);
    s.mask = entering ? (s.mask | (1u << bit)) : (s.mask & ~(1u << bit));
    visible = !before && csgInside(s.mask);
  }
  if (visible) {
    s.found = true;
    s.object = object;
    s.depth = f.depth;
  }
}

vec4 opEnd(inout OpState s, ivec2 pixel, uint count) {
  csgVisible[uint(pixel.y) * uint(uCsgWidth) + uint(pixel.x)] =
      s.found ? uvec2(s.object + 1u, floatBitsToUint(s.depth)) : uvec2(0u);
  return vec4(uBackground, 1.0);
}
