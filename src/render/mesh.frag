// The mesh pass's fragment shader, shared as mesh.vert is: the part's colour, times its texture (a window of it:
// a flat medium's shown part), lit by a lamp above and to the left of the camera plus ambient. Faces turned away
// from the camera are lit as seen from the front (models with open or one-sided faces).
precision highp float;
in vec3 v_pos;
in vec3 v_normal;
in vec2 v_uv;
uniform vec4 colour;
uniform int textured;
uniform int lit;
uniform int normals;
uniform vec4 uv_window;    // the texture's part drawn: min.xy, max.xy
uniform sampler2D tex;
out vec4 result;
void main() {
  vec4 c = colour;
  if (textured != 0) c *= texture(tex, mix(uv_window.xy, uv_window.zw, v_uv));
  if (lit != 0) {
    vec3 n = normals != 0 ? normalize(v_normal) : normalize(cross(dFdx(v_pos), dFdy(v_pos)));
    if (dot(n, -v_pos) < 0.0) n = -n;
    // Camera coordinates: x right, y down, z forward. The lamp is above and left of the camera.
    vec3 to_light = normalize(vec3(-0.35, -0.6, -1.0));
    c.rgb *= 0.4 + 0.6 * max(dot(n, to_light), 0.0);
  }
  result = c;
}
