// The scene's flat media on the phone: pictures, videos, web cards and text cards drawn where the core placed them,
// on a WebGL 2 canvas laid over the camera view. Each quad is drawn as the desktop's compositor draws it (src/render/
// compositor.cpp): texture coordinates per pixel through the inverse of the quad's homography (texture uv to image
// pixels), clamped to the part of the medium shown, image pixel centres at integer coordinates. A text card is drawn
// at the core's layout (the desktop's, media/card_layout.hpp) in the font it was measured with (web/card_font.woff2).
// Solids (cubes, axes, and flat media when the bundle has a calibration) are drawn by mesh_layer.js, in the
// scene's order with the quads, as the compositor draws them.
'use strict';
// eslint-disable-next-line no-unused-vars
class MediaLayer {
  // canvas: the WebGL canvas; file(path): a Promise of the bundle file's Blob; cardFor(url, title): the bundle path of
  // a web card's picture, or ''; askMesh(id): asks the worker for a mesh the core named (its answer goes to mesh());
  // report(message): says what could not be drawn.
  constructor(canvas, file, cardFor, askMesh, report) {
    this.canvas = canvas;
    this.file = file;
    this.report = report;
    this.cardFor = cardFor;
    // Premultiplied: blending SRC_ALPHA, ONE_MINUS_SRC_ALPHA onto a clear canvas leaves colours times alpha, which
    // the page then lays over the camera view as the desktop's compositor lays media over the frame.
    this.gl = canvas.getContext('webgl2', { premultipliedAlpha: true, alpha: true, depth: true });
    this.textures = new Map();   // key -> {texture, source (ImageBitmap or video element), ready, video}
    this.drawn = [];             // the kinds of the quads drawn on the last frame
    if (this.gl) {
      this.program = this.link();
      this.meshes = new MeshLayer(this.gl, askMesh);   // eslint-disable-line no-undef
    }
    this.fontReady = false;      // the cards' font, loaded from the bundle
    const font = new FontFace('ArwbCard', "url(web/card_font.woff2) format('woff2')");
    font.load().then((f) => { document.fonts.add(f); this.fontReady = true; }, () => { this.fontFailed = true; });
  }

  // A text card at the core's layout, as the desktop's cards.cpp draws it: the background's rounded box, then each
  // line from the pad at its baseline.
  static card(c) {
    const canvas = document.createElement('canvas');
    canvas.width = c.width;
    canvas.height = c.height;
    const ctx = canvas.getContext('2d');
    const css = ([r, g, b, a]) => `rgba(${r}, ${g}, ${b}, ${a / 255})`;
    if (c.background[3] > 0) {
      const r = Math.min(c.font_px * 0.3, c.width / 2, c.height / 2);   // cards.cpp's rounded_rect
      const w = c.width, h = c.height;
      ctx.beginPath();
      ctx.arc(w - r, r, r, -Math.PI / 2, 0);
      ctx.arc(w - r, h - r, r, 0, Math.PI / 2);
      ctx.arc(r, h - r, r, Math.PI / 2, Math.PI);
      ctx.arc(r, r, r, Math.PI, 1.5 * Math.PI);
      ctx.closePath();
      ctx.fillStyle = css(c.background);
      ctx.fill();
    }
    ctx.font = `${c.font_px}px ArwbCard`;
    ctx.fillStyle = css(c.colour);
    c.lines.forEach((line, i) => ctx.fillText(line, c.pad, c.pad + i * c.line_h + c.ascent));
    return canvas;
  }

  link() {
    const gl = this.gl;
    const shader = (type, text) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, `#version 300 es
in vec2 pos;
uniform vec2 size;
void main() {
  gl_Position = vec4(2.0 * (pos.x + 0.5) / size.x - 1.0, 1.0 - 2.0 * (pos.y + 0.5) / size.y, 0.0, 1.0);
}`));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, `#version 300 es
precision highp float;
uniform mat3 image_to_uv;
uniform vec2 uv_min;
uniform vec2 uv_max;
uniform float opacity;
uniform vec2 size;
uniform sampler2D tex;
out vec4 colour;
void main() {
  vec3 h = image_to_uv * vec3(gl_FragCoord.x - 0.5, size.y - gl_FragCoord.y - 0.5, 1.0);
  vec2 uv = clamp(h.xy / h.z, uv_min, uv_max);
  vec4 c = texture(tex, uv);
  colour = vec4(c.rgb, c.a * opacity);
}`));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    this.buffer = gl.createBuffer();
    this.at = {};
    for (const name of ['size', 'image_to_uv', 'uv_min', 'uv_max', 'opacity', 'tex'])
      this.at[name] = gl.getUniformLocation(p, name);
    this.pos = gl.getAttribLocation(p, 'pos');
    return p;
  }

  // The texture of an overlay's medium, started on first use (null until its picture is there).
  texture(o, sceneDir, trackKey) {
    let key, path, video = false;
    if (o.kind === 'image') { key = `image ${o.source}`; path = `${sceneDir}/${o.source}`; }
    else if (o.kind === 'video') {
      key = `video ${o.source} ${trackKey}`;
      path = `${sceneDir}/${o.source}`;
      video = true;
    }
    else if (o.kind === 'web') { key = `web ${o.url} ${o.title}`; path = this.cardFor(o.url, o.title); }
    else if (o.kind === 'text' && o.card) {
      if (!this.fontReady) return null;
      key = `text ${JSON.stringify(o.card)}`;
    } else return null;
    if (o.kind === 'text') {
      let t = this.textures.get(key);
      if (!t) {
        t = { texture: null, source: MediaLayer.card(o.card), video: null, ready: true, used: performance.now() };
        this.textures.set(key, t);
      }
      return t;
    }
    return this.fileTexture(key, path, video, !!(o.video && o.video.loop));
  }

  // The texture of a bundle file (a picture, or a video played by a <video>), started on first use.
  fileTexture(key, path, video, loop) {
    return this.blobTexture(key, path, path ? () => this.file(path) : null, video, loop);
  }

  // The texture of a picture or video file's Blob (blob(): a Promise of it), started on first use; `name` is said
  // once if this browser cannot decode it.
  blobTexture(key, name, blob, video, loop) {
    let t = this.textures.get(key);
    if (t) return t;
    t = { texture: null, source: null, video: null, ready: false, used: performance.now() };
    this.textures.set(key, t);
    if (!blob) return t;
    blob().then(async (b) => {
      if (video) {
        const v = document.createElement('video');
        v.muted = true;
        v.loop = loop;
        v.playsInline = true;
        v.src = URL.createObjectURL(b);
        t.video = v;
        t.source = v;
      } else {
        t.source = await createImageBitmap(b);
        t.ready = true;
      }
    }).catch((e) => {
      t.failed = true;
      this.report(`${name}: this browser cannot ${video ? 'play' : 'decode'} it (${e && e.message ? e.message : e})`);
    });
    return t;
  }

  // t's WebGL texture, made on first use and refreshed from a playing video; null until its picture is there.
  glTexture(t, clock, now) {
    if (!t) return null;
    t.used = now;
    if (!t.source) return null;
    if (t.video) this.follow(t, clock);
    if (!t.ready) return null;
    const gl = this.gl;
    // Filtered trilinearly over a mipmap chain, as the desktop's textures of media are (render/texture.hpp): a
    // medium drawn much smaller than its pixels is averaged, not sampled.
    if (!t.texture) {
      t.texture = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, t.texture);
      for (const [k, v] of [[gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR], [gl.TEXTURE_MAG_FILTER, gl.LINEAR],
                            [gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE], [gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE]])
        gl.texParameteri(gl.TEXTURE_2D, k, v);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, t.source);
      gl.generateMipmap(gl.TEXTURE_2D);
    } else if (t.video && t.uploaded !== now) {
      gl.bindTexture(gl.TEXTURE_2D, t.texture);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, t.source);
      gl.generateMipmap(gl.TEXTURE_2D);
    }
    t.uploaded = now;
    return t.texture;
  }

  // A mesh part's texture: the overlay's own medium (a flat medium drawn through the lens), a model's picture (its
  // encoded bytes, from the core), or a picture the core named by its path in its file system (/files/ + the
  // bundle path: a cube's face).
  partTexture(o, part, sceneDir, now) {
    if (part.overlay_texture) return this.glTexture(this.texture(o, sceneDir, o.track), o.video, now);
    if (part.pictureBlob) {
      const t = this.blobTexture(part.pictureKey, part.pictureName, () => Promise.resolve(part.pictureBlob));
      return this.glTexture(t, null, now);
    }
    if (!part.texture || !part.texture.startsWith('/files/')) return null;
    const path = part.texture.slice('/files/'.length);
    return this.glTexture(this.fileTexture(`image ${path}`, path, false, false), null, now);
  }

  // A mesh from the worker (MeshLayer.add).
  mesh(msg) { if (this.meshes) this.meshes.add(msg); }

  // A video element following the core's clock: playing or paused as the scene says, and sought only when more
  // than a quarter second off, as the desktop's player waits for a wobbling clock (media/media_store.hpp).
  follow(t, clock) {
    const v = t.video;
    if (!v || !clock) return;
    const d = v.duration;
    let at = clock.t;
    if (Number.isFinite(d) && d > 0) at = clock.loop ? at % d : Math.min(at, d);
    if (!v.seeking && Math.abs(v.currentTime - at) > 0.25) v.currentTime = at;
    if (clock.playing && v.paused) v.play().catch(() => {});
    if (!clock.playing && !v.paused) v.pause();
    t.ready = t.ready || v.readyState >= 2;   // once it has a picture, the last one stays while it seeks
  }

  // Draws the overlays of the frame the core searched (width x height, the camera's picture) over the view.
  draw(overlays, width, height, sceneDir) {
    const gl = this.gl;
    this.drawn = [];
    if (!gl || !this.program) return;
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    gl.viewport(0, 0, width, height);
    gl.clearColor(0, 0, 0, 0);
    gl.clearDepth(1);
    gl.depthMask(true);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.BLEND);
    gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
    const now = performance.now();
    for (const o of overlays || []) {
      if (o.solid) {
        if (o.solid.mesh && this.meshes && this.meshes.draw(o, (part) => this.partTexture(o, part, sceneDir, now)))
          this.drawn.push(o.kind);
        continue;
      }
      const texture = this.glTexture(this.texture(o, sceneDir, o.track), o.video, now);
      if (!texture) continue;
      gl.useProgram(this.program);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer);
      gl.enableVertexAttribArray(this.pos);
      gl.vertexAttribPointer(this.pos, 2, gl.FLOAT, false, 0, 0);
      gl.uniform2f(this.at.size, width, height);
      gl.bindTexture(gl.TEXTURE_2D, texture);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
      gl.uniform1i(this.at.tex, 0);
      gl.uniformMatrix3fv(this.at.image_to_uv, false, MediaLayer.inverseColumnMajor(o.quad.H));
      gl.uniform2f(this.at.uv_min, o.quad.uv_min[0], o.quad.uv_min[1]);
      gl.uniform2f(this.at.uv_max, o.quad.uv_max[0], o.quad.uv_max[1]);
      gl.uniform1f(this.at.opacity, o.quad.opacity);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(o.quad.corners.flat()), gl.DYNAMIC_DRAW);
      gl.drawArrays(gl.TRIANGLE_FAN, 0, 4);
      this.drawn.push(o.kind);
    }
    if (this.meshes) this.meshes.forget(now - 5000);
    this.forget(now - 5000);
  }

  // Media not drawn since `before` (a marker gone, a video of a track that left): their textures and players go.
  forget(before) {
    for (const [key, t] of this.textures) {
      if (t.used === undefined || t.used >= before) continue;
      if (t.texture) this.gl.deleteTexture(t.texture);
      if (t.video) {
        t.video.pause();
        URL.revokeObjectURL(t.video.src);
      }
      if (t.source && t.source.close) t.source.close();
      this.textures.delete(key);
    }
  }

  // The inverse of a row-major 3x3 (the core's H: uv to image), as WebGL's column-major mat3.
  static inverseColumnMajor(h) {
    const [a, b, c, d, e, f, g, i, j] = h;
    const A = e * j - f * i, B = -(d * j - f * g), C = d * i - e * g;
    const det = a * A + b * B + c * C;
    const inv = [A, -(b * j - c * i), b * f - c * e,
                 B, a * j - c * g, -(a * f - c * d),
                 C, -(a * i - b * g), a * e - b * d].map((v) => v / det);
    // Row-major inv -> column-major: transpose.
    return new Float32Array([inv[0], inv[3], inv[6], inv[1], inv[4], inv[7], inv[2], inv[5], inv[8]]);
  }
}
