// The scene's solids on the phone: cubes, axes, and flat media drawn through the lens model when the bundle has a
// calibration, drawn as the desktop's MeshRenderer draws them (src/render/mesh_renderer.cpp): the same shaders
// (mesh_shaders.js, written by web/build-core from src/render/mesh.vert and mesh.frag), the same uniforms (the
// core's, render/mesh_uniforms.hpp), the same vertices (the core's, by mesh id) and a depth buffer. Only y_sign
// differs: the canvas's top row is at the top.
'use strict';
// eslint-disable-next-line no-unused-vars
class MeshLayer {
  // gl: the media layer's WebGL 2 context; ask(id): asks the worker for a mesh the core named (answered by add).
  constructor(gl, ask) {
    this.gl = gl;
    this.ask = ask;
    this.meshes = new Map();   // id -> {parts: [{vao, vbo, ebo, count, meta}], used} or {asked: true, used}
    this.program = this.link();
  }

  link() {
    const gl = this.gl;
    const shader = (type, body) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, `#version 300 es\n${body}`);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const p = gl.createProgram();
    // eslint-disable-next-line no-undef
    gl.attachShader(p, shader(gl.VERTEX_SHADER, MESH_SHADERS.vertex));
    // eslint-disable-next-line no-undef
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, MESH_SHADERS.fragment));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    this.at = {};
    for (const name of ['model_view', 'normal_matrix', 'intrinsics', 'skew', 'knum', 'kden', 'tangential', 'r2_max',
                        'size', 'depth', 'y_sign', 'colour', 'textured', 'lit', 'normals', 'uv_window', 'tex'])
      this.at[name] = gl.getUniformLocation(p, name);
    return p;
  }

  // A mesh from the worker: {id, source, parts: [{vertices: Float32Array, indices: Uint32Array, colour, lit, normals,
  // uvs, overlay_texture, texture, picture}], pictures: [Uint8Array]} (a model's textures as picture files, a
  // part's by index), or {id, error}: asked for, or sent ahead of the first frame that draws it.
  add(msg) {
    const gl = this.gl;
    const old = this.meshes.get(msg.id) || { used: performance.now() };
    if (old.parts) return;   // asked for again while the worker was sending it
    if (msg.error) { this.meshes.set(msg.id, Object.assign(old, { error: msg.error })); return; }
    const blobs = (msg.pictures || []).map((bytes) => new Blob([bytes]));
    const parts = msg.parts.map((meta) => {
      if (meta.picture >= 0 && meta.picture < blobs.length) {
        meta.pictureBlob = blobs[meta.picture];
        meta.pictureKey = `mesh ${msg.id} picture ${meta.picture}`;
        meta.pictureName = `${msg.source}: texture of material '${meta.name}'`;
      }
      const vao = gl.createVertexArray(), vbo = gl.createBuffer(), ebo = gl.createBuffer();
      gl.bindVertexArray(vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, vbo);
      gl.bufferData(gl.ARRAY_BUFFER, meta.vertices, gl.STATIC_DRAW);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ebo);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, meta.indices, gl.STATIC_DRAW);
      const stride = 8 * 4;   // render::interleaved_vertices: position, normal, uv
      for (const [at, n, offset] of [[0, 3, 0], [1, 3, 12], [2, 2, 24]]) {
        gl.enableVertexAttribArray(at);
        gl.vertexAttribPointer(at, n, gl.FLOAT, false, stride, offset);
      }
      gl.bindVertexArray(null);
      const count = meta.indices.length;
      return { vao, vbo, ebo, count, meta: Object.assign({}, meta, { vertices: null, indices: null }) };
    });
    this.meshes.set(msg.id, { parts, used: old.used });
  }

  // Draws overlay o's solid; texture(part) gives a part's WebGL texture, or null while it has none. False while its
  // mesh is on its way.
  draw(o, texture) {
    const gl = this.gl;
    const id = o.solid.mesh;
    let m = this.meshes.get(id);
    if (!m) {
      m = { asked: true, used: performance.now() };
      this.meshes.set(id, m);
      this.ask(id);
    }
    m.used = performance.now();
    if (!m.parts) return false;
    const u = o.solid.uniforms;
    gl.useProgram(this.program);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LESS);
    // Row-major from the core, as the desktop passes them with transpose set; WebGL takes column-major.
    gl.uniformMatrix4fv(this.at.model_view, false, MeshLayer.transpose(u.model_view, 4));
    gl.uniformMatrix3fv(this.at.normal_matrix, false, MeshLayer.transpose(u.normal_matrix, 3));
    gl.uniform4fv(this.at.intrinsics, u.intrinsics);
    gl.uniform1f(this.at.skew, u.skew);
    gl.uniform3fv(this.at.knum, u.knum);
    gl.uniform3fv(this.at.kden, u.kden);
    gl.uniform2fv(this.at.tangential, u.tangential);
    gl.uniform1f(this.at.r2_max, u.r2_max);
    gl.uniform2fv(this.at.size, u.size);
    gl.uniform2fv(this.at.depth, u.depth);
    gl.uniform1f(this.at.y_sign, -1);
    gl.uniform1i(this.at.tex, 0);
    for (const part of m.parts) {
      const p = part.meta;
      if (part.count === 0) continue;
      const t = p.uvs ? texture(p) : null;
      if (t) {
        gl.bindTexture(gl.TEXTURE_2D, t);
        // Models' texture coordinates may run past 0..1 and repeat; a flat medium stays clamped at its edges.
        const wrap = p.overlay_texture ? gl.CLAMP_TO_EDGE : gl.REPEAT;
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, wrap);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, wrap);
      } else if (p.overlay_texture) continue;   // a flat medium without its picture yet
      gl.uniform4f(this.at.colour, p.colour[0], p.colour[1], p.colour[2], p.colour[3] * o.quad.opacity);
      gl.uniform1i(this.at.textured, t ? 1 : 0);
      if (p.overlay_texture) gl.uniform4f(this.at.uv_window, o.quad.uv_min[0], o.quad.uv_min[1], o.quad.uv_max[0],
                                          o.quad.uv_max[1]);
      else gl.uniform4f(this.at.uv_window, 0, 0, 1, 1);
      gl.uniform1i(this.at.lit, p.lit ? 1 : 0);
      gl.uniform1i(this.at.normals, p.normals ? 1 : 0);
      gl.bindVertexArray(part.vao);
      gl.drawElements(gl.TRIANGLES, part.count, gl.UNSIGNED_INT, 0);
    }
    gl.bindVertexArray(null);
    gl.disable(gl.DEPTH_TEST);
    return true;
  }

  // Meshes not drawn since `before`: their buffers go (one the core names again is asked for again).
  forget(before) {
    const gl = this.gl;
    for (const [id, m] of this.meshes) {
      if (m.used >= before) continue;
      for (const p of m.parts || []) {
        gl.deleteVertexArray(p.vao);
        gl.deleteBuffer(p.vbo);
        gl.deleteBuffer(p.ebo);
      }
      this.meshes.delete(id);
    }
  }

  static transpose(a, n) {
    const t = new Float32Array(n * n);
    for (let r = 0; r < n; ++r) for (let c = 0; c < n; ++c) t[c * n + r] = a[r * n + c];
    return t;
  }
}
