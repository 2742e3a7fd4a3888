// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] The fragment payload every method stores (8 bytes: packed RGBA8 colour + float32 window depth,
// the layout of the A-buffer and k-buffer papers, so memory figures compare with theirs).
#ifndef MFR_PAYLOAD_GLSL
#define MFR_PAYLOAD_GLSL
struct MfrFragment {
  uint color;   // packUnorm4x8(RGBA)
  float depth;  // gl_FragCoord.z
};

uvec2 mfrPack(MfrFragment f) { return uvec2(f.color, floatBitsToUint(f.depth)); }
MfrFragment mfrUnpack(uvec2 v) { return MfrFragment(v.x, uintBitsToFloat(v.y)); }
#endif
