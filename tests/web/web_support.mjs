// What the web tests share: the WebAssembly core loaded in Node, and PNG files read as RGBA.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

// npm's packages as web/package.json lists them, from web/node_modules (third_party/setup installs them), whatever
// NODE_PATH says.
export const webRequire = createRequire(new URL('../../web/package.json', import.meta.url));
const require = createRequire(import.meta.url);
const { PNG } = webRequire('pngjs');

// The core built by web/core (arwb_core.js beside arwb_core.wasm), with its C functions wrapped for JavaScript.
// Its detector searches each frame whole, as `arwb detect` searches still images; { video: true } keeps the page's
// video mode (around the last frame's markers), as `arwb render` and the workbench search a video.
export async function loadCore(coreJs, { video = false } = {}) {
  const ArwbCore = require(path.resolve(coreJs));
  const wasmBinary = fs.readFileSync(coreJs.replace(/\.js$/, '.wasm'));
  const m = await ArwbCore({ wasmBinary });
  const setDictionaries = m.cwrap('arwb_set_dictionaries', 'string', ['string']);
  const setParam = m.cwrap('arwb_set_param', 'string', ['string', 'number']);
  const frame = m.cwrap('arwb_frame', 'number', ['number', 'number']);
  const detect = m.cwrap('arwb_detect', 'string', []);
  const setCamera = m.cwrap('arwb_set_camera', 'string', ['string', 'number']);
  if (!video) setParam('full_search_interval', 1);
  const sceneLoad = m.cwrap('arwb_scene_load', 'string', ['string']);
  const sceneVideo = m.cwrap('arwb_scene_video', null, ['string', 'number', 'number', 'number']);
  const sceneStep = m.cwrap('arwb_scene_step', 'string', ['number']);
  const sceneMesh = m.cwrap('arwb_scene_mesh', 'string', ['number']);
  const sceneSelfTest = m.cwrap('arwb_scene_self_test', 'string', ['string']);
  return {
    setDictionaries,
    setParam,
    // A calibration file's path in the module's file system ("" for the default camera), the markers' side.
    setCamera,
    // Bytes (a Buffer or string) as a file of the module's file system, its folders made first.
    writeFile(file, bytes) {
      m.FS.mkdirTree(path.posix.dirname(file));
      m.FS.writeFile(file, bytes);
    },
    // The scene at a path of the module's file system: its status, parsed.
    sceneLoad: (file) => JSON.parse(sceneLoad(file)),
    // A video's size and length, as the page's <video> reads them.
    sceneVideo,
    // The tracker and the scene on the last detections at t seconds: the overlays as the core's JSON, parsed.
    sceneStep: (t) => JSON.parse(sceneStep(t)),
    // The bundle's self-test on a scene file of the module's file system: its rows, parsed.
    sceneSelfTest: (file) => JSON.parse(sceneSelfTest(file)),
    // A mesh a step named, parsed, with its pictures' bytes copied out as Buffers.
    sceneMesh(id) {
      const r = JSON.parse(sceneMesh(id));
      if (r.pictures) r.pictures = r.pictures.map((p) => Buffer.from(m.HEAPU8.slice(p.bytes, p.bytes + p.length)));
      return r;
    },
    // image: {width, height, data: RGBA bytes}. The detections as the core's JSON, parsed.
    detect(image) {
      const at = frame(image.width, image.height);
      if (!at) return { error: `a frame of ${image.width}x${image.height} is out of 1..8192 a side` };
      m.HEAPU8.set(image.data, at);
      return JSON.parse(detect());
    },
  };
}

export function readPng(file) {
  return PNG.sync.read(fs.readFileSync(file));
}

// Frames (RGBA images of one size) as a YUV4MPEG2 file, 4:2:0, BT.601 full range: what Chromium's fake camera
// (--use-file-for-fake-video-capture) plays in a loop.
export function writeY4m(file, images, fps = 10) {
  const { width: w, height: h } = images[0];
  const cw = Math.ceil(w / 2), ch = Math.ceil(h / 2);
  const parts = [Buffer.from(`YUV4MPEG2 W${w} H${h} F${fps}:1 Ip A1:1 C420jpeg\n`)];
  for (const img of images) {
    if (img.width !== w || img.height !== h) throw new Error(`y4m frames must share one size (${w}x${h})`);
    const y = Buffer.alloc(w * h), u = Buffer.alloc(cw * ch), v = Buffer.alloc(cw * ch);
    const px = (i) => [img.data[i], img.data[i + 1], img.data[i + 2]];
    for (let r = 0; r < h; r++)
      for (let c = 0; c < w; c++) {
        const [R, G, B] = px((r * w + c) * 4);
        y[r * w + c] = Math.round(0.299 * R + 0.587 * G + 0.114 * B);
      }
    for (let r = 0; r < ch; r++)
      for (let c = 0; c < cw; c++) {
        let R = 0, G = 0, B = 0, n = 0;
        for (let dr = 0; dr < 2; dr++)
          for (let dc = 0; dc < 2; dc++) {
            const rr = Math.min(h - 1, 2 * r + dr), cc = Math.min(w - 1, 2 * c + dc);
            const [r8, g8, b8] = px((rr * w + cc) * 4);
            R += r8; G += g8; B += b8; n++;
          }
        R /= n; G /= n; B /= n;
        const clamp = (x) => Math.max(0, Math.min(255, Math.round(x)));
        u[r * cw + c] = clamp(128 - 0.168736 * R - 0.331264 * G + 0.5 * B);
        v[r * cw + c] = clamp(128 + 0.5 * R - 0.418688 * G - 0.081312 * B);
      }
    parts.push(Buffer.from('FRAME\n'), y, u, v);
  }
  fs.writeFileSync(file, Buffer.concat(parts));
}

// A static server on 127.0.0.1 (a free port) of the files in `folders`, the first that has a path winning (a
// folder's subfolders included). Every path asked for is kept in `served` (with its status), so a test can say
// what the page fetched. `isolated`: with the headers that make the page cross-origin isolated, where
// performance.now() is precise to microseconds, not to a tenth of a millisecond (the bench's).
export async function serve(folders, { isolated = false } = {}) {
  const http = await import('node:http');
  const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.css': 'text/css',
                  '.wasm': 'application/wasm', '.json': 'application/json', '.png': 'image/png' };
  const served = [];
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://127.0.0.1');
    let pathname = decodeURIComponent(url.pathname);
    if (pathname.endsWith('/')) pathname += 'index.html';
    const parts = pathname.split('/').filter(Boolean);
    const file = parts.includes('..') ? null
      : folders.map((f) => path.join(f, ...parts)).find((f) => fs.existsSync(f) && fs.statSync(f).isFile());
    if (!file) {
      served.push({ path: pathname, status: 404 });
      res.writeHead(404).end('not found');
      return;
    }
    served.push({ path: pathname, status: 200 });
    const isolation = isolated ? { 'Cross-Origin-Opener-Policy': 'same-origin',
                                   'Cross-Origin-Embedder-Policy': 'require-corp' } : {};
    res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream',
                         'Cache-Control': 'no-store', ...isolation });
    fs.createReadStream(file).pipe(res);
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { url: `http://127.0.0.1:${server.address().port}/`, served, close: () => server.close() };
}

// `arwb serve BUNDLE --port 0`, as a person serves a bundle: resolves once it has printed its address. `served` is
// its request log (stderr), a line per request answered; close() stops it (SIGTERM) and waits for it to end.
export async function arwbServe(arwb, bundle) {
  const { spawn } = await import('node:child_process');
  const child = spawn(arwb, ['serve', bundle, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
  const served = [];
  let err = '';
  child.stderr.setEncoding('utf8');
  child.stderr.on('data', (text) => {
    err += text;
    served.push(...text.split('\n').filter((l) => /^[A-Z]+ \//.test(l)));
  });
  const ended = new Promise((resolve) => child.on('exit', resolve));
  const url = await new Promise((resolve, reject) => {
    let out = '';
    child.stdout.setEncoding('utf8');
    child.stdout.on('data', (text) => {
      out += text;
      const m = out.match(/^ +(http:\/\/127\.0\.0\.1:\d+\/)$/m);
      if (m) resolve(m[1]);
    });
    ended.then((code) => reject(new Error(`arwb serve ended (${code}) before saying its address: ${err}`)));
  });
  return { url, served, close: async () => { child.kill('SIGTERM'); await ended; } };
}

// What a test compares: `got` (the core's or the page's result) against `want` (a line of `arwb detect --json`) for
// one frame. Adds to `tally` the markers compared and the largest corner difference; returns a problem or null.
export function compareWithNative(frame, got, want, tally) {
  const ids = (list) => list.map((m) => `${m.dict}:${m.id}`).join(' ');
  if (ids(got.markers) !== ids(want.markers))
    return `${frame}: found [${ids(got.markers)}], arwb detect found [${ids(want.markers)}]`;
  got.markers.forEach((m, i) => m.corners.forEach(([x, y], k) => {
    const [wx, wy] = want.markers[i].corners[k];
    tally.worst = Math.max(tally.worst, Math.abs(x - wx), Math.abs(y - wy));
  }));
  tally.markers += got.markers.length;
  return null;
}

// The verdict on a tally: problems when nothing was compared or a corner is off by more than 1e-3 px.
export function tallyProblems(tally) {
  const problems = [];
  if (tally.markers === 0) problems.push('no marker was found in any frame: nothing was compared');
  if (tally.worst > 1e-3) problems.push(`corners differ by up to ${tally.worst.toFixed(6)} px (allowed 0.001)`);
  return problems;
}
