// The mesh pass's vertex shader, shared by the desktop (render/mesh_renderer.cpp, as GLSL 3.30) and the phone
// player (web/player/mesh_layer.js, as GLSL ES 3.00): each prepends its #version line. Uniforms as
// render/mesh_uniforms.hpp computes them. Pixel centres at integer coordinates; y_sign 1 puts the image's top row
// at the framebuffer's row 0 (the desktop reads its framebuffer back), -1 at the top of a canvas. The clip
// position is the pinhole's, linear in the camera point, so clipping against the near plane is exact; in front of
// the camera its x and y are replaced by the distorted projection's (times z, so the division gives it).
precision highp float;
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
layout(location = 2) in vec2 uv;
uniform mat4 model_view;
uniform mat3 normal_matrix;
uniform vec4 intrinsics;   // fx fy cx cy
uniform float skew;
uniform vec3 knum;         // k1 k2 k3
uniform vec3 kden;         // k4 k5 k6
uniform vec2 tangential;   // p1 p2
uniform float r2_max;
uniform vec2 size;
uniform vec2 depth;        // clip z = depth.x * z + depth.y
uniform float y_sign;
out vec3 v_pos;
out vec3 v_normal;
out vec2 v_uv;
void main() {
  vec4 c = model_view * vec4(pos, 1.0);
  v_pos = c.xyz;
  v_normal = normal_matrix * nrm;
  v_uv = uv;
  float z = c.z;
  vec2 px_z = vec2(intrinsics.x * c.x + skew * c.y + intrinsics.z * z, intrinsics.y * c.y + intrinsics.w * z);
  if (z > 1e-6) {
    vec2 xy = c.xy / z;
    float r2 = dot(xy, xy);
    if (r2 > r2_max) { xy *= sqrt(r2_max / r2); r2 = r2_max; }
    float r4 = r2 * r2, r6 = r4 * r2;
    float radial = (1.0 + knum.x * r2 + knum.y * r4 + knum.z * r6) / (1.0 + kden.x * r2 + kden.y * r4 + kden.z * r6);
    vec2 d = xy * radial + vec2(2.0 * tangential.x * xy.x * xy.y + tangential.y * (r2 + 2.0 * xy.x * xy.x),
                                tangential.x * (r2 + 2.0 * xy.y * xy.y) + 2.0 * tangential.y * xy.x * xy.y);
    // Held at the limit's radius, a far vertex keeps its direction from the centre.
    if (dot(c.xy / z, c.xy / z) > r2_max) d *= sqrt(dot(c.xy / z, c.xy / z) / r2_max);
    px_z = vec2(intrinsics.x * d.x + skew * d.y + intrinsics.z, intrinsics.y * d.y + intrinsics.w) * z;
  }
  vec2 ndc = 2.0 * (px_z + 0.5 * z) / size - z;
  gl_Position = vec4(ndc.x, y_sign * ndc.y, depth.x * z + depth.y, z);
}
