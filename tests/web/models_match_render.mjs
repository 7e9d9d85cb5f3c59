// Model files and flat cards on the phone without a calibration (the assumed camera), against `arwb render`
// (render_support.mjs): an OBJ box with its material library and a picture file (map_Kd) on marker 0, a GLB box
// whose picture is inside the file (an image in a buffer view) on marker 1, and a web card, a text card and a video
// drawn as flat quads on marker 2; a tap on the web card opens its link. Run by ctest as
//   node --no-experimental-fetch models_match_render.mjs ARWB CORE_JS
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { comparisonTest, judge, pageAgainstRender } from './render_support.mjs';

const [arwb] = process.argv.slice(2);
const museum = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../scripts/museum');

// A box of side 1 standing on y = 0 (models are written y up), each face's four corners with the texture's corners.
function boxFaces() {
  const faces = [];
  for (const [axis, sign] of [[0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1]]) {
    const [u, v] = [0, 1, 2].filter((a) => a !== axis);
    faces.push([[0, 0], [1, 0], [1, 1], [0, 1]].map(([a, b]) => {
      const p = [0, 0, 0];
      p[axis] = 0.5 * sign;
      p[u] = a - 0.5;
      p[v] = b - 0.5;
      p[1] += 0.5;
      return { p, uv: [a, b] };
    }));
  }
  return faces;
}

// The box as OBJ text (faces by 1-based indices of their own corners).
function boxObj(mtl) {
  const lines = [`mtllib ${mtl}`, 'usemtl painted'];
  const faces = boxFaces();
  for (const f of faces) for (const c of f) lines.push(`v ${c.p.join(' ')}`, `vt ${c.uv.join(' ')}`);
  faces.forEach((f, i) => lines.push(`f ${[1, 2, 3, 4].map((k) => `${i * 4 + k}/${i * 4 + k}`).join(' ')}`));
  return `${lines.join('\n')}\n`;
}

// The box as a GLB whose one material's base colour texture is `png`, stored in the binary chunk.
function boxGlb(png) {
  const corners = boxFaces().flat();
  const positions = Buffer.from(new Float32Array(corners.flatMap((c) => c.p)).buffer);
  const uvs = Buffer.from(new Float32Array(corners.flatMap((c) => c.uv)).buffer);
  const indices = Buffer.from(new Uint16Array([...Array(6).keys()].flatMap((f) => [0, 1, 2, 0, 2, 3]
    .map((k) => f * 4 + k))).buffer);
  const views = [positions, uvs, indices, png];
  const offsets = [];
  let at = 0;
  for (const v of views) { offsets.push(at); at += Math.ceil(v.length / 4) * 4; }
  const bin = Buffer.alloc(at);
  views.forEach((v, i) => v.copy(bin, offsets[i]));
  const json = {
    asset: { version: '2.0' }, scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0, TEXCOORD_0: 1 }, indices: 2, material: 0 }] }],
    materials: [{ name: 'picture', pbrMetallicRoughness: { baseColorTexture: { index: 0 } } }],
    textures: [{ source: 0 }], images: [{ bufferView: 3, mimeType: 'image/png' }],
    accessors: [
      { bufferView: 0, componentType: 5126, count: 24, type: 'VEC3', min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5] },
      { bufferView: 1, componentType: 5126, count: 24, type: 'VEC2' },
      { bufferView: 2, componentType: 5123, count: 36, type: 'SCALAR' }],
    bufferViews: views.map((v, i) => ({ buffer: 0, byteOffset: offsets[i], byteLength: v.length })),
    buffers: [{ byteLength: bin.length }],
  };
  let text = Buffer.from(JSON.stringify(json));
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const header = Buffer.alloc(12), jsonHead = Buffer.alloc(8), binHead = Buffer.alloc(8);
  header.write('glTF', 0, 'latin1');
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + text.length + 8 + bin.length, 8);
  jsonHead.writeUInt32LE(text.length, 0);
  jsonHead.writeUInt32LE(0x4e4f534a, 4);   // "JSON"
  binHead.writeUInt32LE(bin.length, 0);
  binHead.writeUInt32LE(0x004e4942, 4);    // "BIN\0"
  return Buffer.concat([header, jsonHead, text, binHead, bin]);
}

// A finger's tap on the web card's middle, and one in the frame's top-left corner, away from every medium: what
// each opened (window.open recorded, not followed).
async function tapCard(page) {
  const at = await page.evaluate(`(() => {
    const o = arwbPlayer.scene.overlays.find((x) => x.kind === 'web');
    const v = document.getElementById('view'), r = v.getBoundingClientRect();
    const s = Math.min(r.width / v.width, r.height / v.height);
    const left = r.left + (r.width - v.width * s) / 2, top = r.top + (r.height - v.height * s) / 2;
    const [x, y] = o.quad.corners.reduce(([a, b], [cx, cy]) => [a + cx / 4, b + cy / 4], [0, 0]);
    window.opened = [];
    window.open = (url) => { window.opened.push(url); return null; };
    return { url: o.url, x: left + (x + 0.5) * s, y: top + (y + 0.5) * s, corner: [left + 4, top + 4] };
  })()`);
  await page.tap(at.x, at.y);
  const opened = await page.evaluate('window.opened.splice(0)');
  await page.tap(...at.corner);
  return { url: at.url, opened, missed: await page.evaluate('window.opened') };
}

await comparisonTest('arwb-models-', async (tmp, fail) => {
  const sceneDir = path.join(tmp, 'scene');
  const models = path.join(sceneDir, 'models');
  fs.mkdirSync(models, { recursive: true });
  fs.copyFileSync(path.join(museum, 'media', 'composition.png'), path.join(models, 'composition.png'));
  fs.writeFileSync(path.join(models, 'box.mtl'), 'newmtl painted\nKd 1 1 1\nmap_Kd composition.png\n');
  fs.writeFileSync(path.join(models, 'box.obj'), boxObj('box.mtl'));
  fs.writeFileSync(path.join(models, 'box.glb'), boxGlb(fs.readFileSync(path.join(museum, 'media', 'sunset.png'))));
  // A video that shows one picture throughout, so that the page's frame, at whatever time it plays, is the one
  // arwb render decodes (H.264, as phones play).
  fs.mkdirSync(path.join(sceneDir, 'media'));
  execFileSync('ffmpeg', ['-v', 'error', '-loop', '1', '-i', path.join(museum, 'media', 'composition.png'), '-t', '4',
                          '-r', '10', '-vf', 'scale=320:240,format=yuv420p', '-c:v', 'libx264', '-movflags',
                          '+faststart', path.join(sceneDir, 'media', 'still.mp4')]);
  const scene = path.join(sceneDir, 'models.lua');
  fs.writeFileSync(scene, [
    'dictionary "ARUCO_ORIGINAL"',
    'marker(0, { media = model("models/box.obj", { size = 0.8, rotate = {0, 0, 30} }) })',
    'marker(1, { media = model("models/box.glb", { size = 0.8 }) })',
    'marker(2, { media = web("https://www.lua.org", { title = "Lua" }), place = on_marker { scale = 1.1 } })',
    'marker(2, { media = text("a card", { size = 28, colour = "#202020", background = "#f0f0f0c0" }),',
    '            place = beside { side = "top", gap = 0.1, size = 0.4 } })',
    'marker(2, { media = video("media/still.mp4", { loop = true }), place = beside { side = "bottom", gap = 0.1 } })',
    ''].join('\n'));
  const r = await pageAgainstRender({ arwb, tmp, scene, calib: '', kinds: ['model', 'web', 'text', 'video'],
                                       then: tapCard });
  judge(r, 2000, fail);
  const { url, opened, missed } = r.then;
  if (opened.length !== 1 || opened[0] !== url) fail(`a tap on the web card opened [${opened}], not ${url}`);
  if (missed.length) fail(`a tap beside the markers opened [${missed}]`);
  console.log(`a tap on the web card opened ${opened.join(', ')}; one beside the markers opened nothing`);
});
