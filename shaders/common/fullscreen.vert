// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] Full-screen triangle for screen passes (resolve, blend); no vertex buffer needed.
void main() {
  const vec2 corners[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
  gl_Position = vec4(corners[gl_VertexID], 0.0, 1.0);
}
