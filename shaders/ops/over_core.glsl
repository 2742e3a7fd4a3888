// Front-to-back "over" compositing state (Porter & Duff 1984), shared by the operations "oit" and
// "hybrid" (whose core is composited the same way). Same arithmetic, in the same order, as the
// oracle's compositeOver (mfrcore/src/reference/composite.cpp).
uniform vec3 uBackground;

struct OpState {
  vec3 color;
  float transmittance;
};

void opBegin(inout OpState s, ivec2 pixel) {
  s.color = vec3(0.0);
  s.transmittance = 1.0;
}

void opFragment(inout OpState s, MfrFragment f, uint position) {
  vec4 c = unpackUnorm4x8(f.color);
  s.color += s.transmittance * c.a * vec3(c);
  s.transmittance *= 1.0 - c.a;
}
