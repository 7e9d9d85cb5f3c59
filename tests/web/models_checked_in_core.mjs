// The WebAssembly core reads a scene's model files with the desktop's loader and checks: an OBJ's picture file
// (map_Kd) reaches the page as that file's bytes; a texture phones' browsers cannot show is named with the reason and
// its model still drawn in its colour; a missing model and a model leaving the scene's folder are refused with the
// desktop's messages (`arwb render`'s on the same frame). Run by ctest as
//   node --no-experimental-fetch models_checked_in_core.mjs ARWB CORE_JS
import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { loadCore, readPng } from './web_support.mjs';

const [arwb, coreJs] = process.argv.slice(2);
const museum = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../scripts/museum');
const failures = [];
const fail = (message) => failures.push(message);

// A square of two triangles with texture coordinates, as OBJ, painted with `picture`.
const squareObj = (mtl) => `mtllib ${mtl}\nusemtl painted\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n` +
  'vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n';

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-model-core-'));
try {
  const sceneDir = path.join(tmp, 'scene');
  fs.mkdirSync(path.join(sceneDir, 'models'), { recursive: true });
  const w = (rel, bytes) => fs.writeFileSync(path.join(sceneDir, rel), bytes);
  const png = fs.readFileSync(path.join(museum, 'media', 'sunset.png'));
  w('models/png.png', png);
  w('models/png.mtl', 'newmtl painted\nmap_Kd png.png\n');
  w('models/png.obj', squareObj('png.mtl'));
  // A 4x4 grey PGM, which the desktop decodes and phones' browsers do not.
  w('models/grey.pgm', Buffer.concat([Buffer.from('P5\n4 4\n255\n'), Buffer.alloc(16, 128)]));
  w('models/grey.mtl', 'newmtl painted\nKd 0.2 0.4 0.6\nmap_Kd grey.pgm\n');
  w('models/grey.obj', squareObj('grey.mtl'));
  const scene = path.join(sceneDir, 'models.lua');
  w('models.lua', ['dictionary "ARUCO_ORIGINAL"',
                   'marker(0, { media = model("models/png.obj") })',
                   'marker(1, { media = model("models/grey.obj") })',
                   'marker(2, { media = model("models/none.obj") })',
                   'marker(2, { media = model("../outside.obj") })', ''].join('\n'));
  fs.writeFileSync(path.join(tmp, 'outside.obj'), squareObj('x.mtl'));

  // A frame of the synthetic source with markers 0, 1 and 2.
  const empty = path.join(tmp, 'empty.lua');
  fs.writeFileSync(empty, 'dictionary "ARUCO_ORIGINAL"\n');
  const frames = path.join(tmp, 'frames');
  execFileSync(arwb, ['render', '--scene', empty, '--input', 'synthetic', '--frames', '1', '--out', frames],
               { stdio: 'pipe' });
  const frame = readPng(path.join(frames, 'frame_000000.png'));

  const core = await loadCore(coreJs);
  for (const rel of ['models.lua', 'models/png.png', 'models/png.mtl', 'models/png.obj', 'models/grey.pgm',
                     'models/grey.mtl', 'models/grey.obj'])
    core.writeFile(`/files/scene/${rel}`, fs.readFileSync(path.join(sceneDir, rel)));
  core.writeFile('/files/outside.obj', fs.readFileSync(path.join(tmp, 'outside.obj')));
  const status = core.sceneLoad('/files/scene/models.lua');
  if (!status.ok) throw new Error(`the scene did not load: ${status.error}`);
  core.setCamera('', 1);
  const ids = core.detect(frame).markers.map((m) => m.id);
  if (![0, 1, 2].every((id) => ids.includes(id))) throw new Error(`the frame shows markers ${ids.join(', ')}`);
  const step = core.sceneStep(0);
  const errors = step.errors.join('\n');
  const warnings = (step.scene.console || []).filter((l) => l.level === 1).map((l) => l.text).join('\n');
  const models = step.overlays.filter((o) => o.kind === 'model');
  if (models.length !== 2) fail(`${models.length} models drawn, not 2 (png.obj and grey.obj)`);

  // The desktop's words for the same scene on the same frame: arwb render's "scene: " lines, by line of the scene.
  const rendered = spawnSync(arwb, ['render', '--scene', scene, '--input', frames, '--out', path.join(tmp, 'out')],
                             { encoding: 'utf8' });
  const byLine = (lines, file) => lines.filter((l) => l.startsWith(file)).map((l) => l.slice(file.length)).sort();
  const native = byLine(rendered.stderr.split('\n').map((l) => l.replace(/^scene: /, '')), scene);
  const web = byLine(step.errors, '/files/scene/models.lua');
  if (native.length !== 2 || JSON.stringify(web) !== JSON.stringify(native))
    fail(`the core said\n  ${web.join('\n  ')}\narwb render said\n  ${native.join('\n  ')}`);
  const pgm = "models/grey.obj: material 'painted' map_Kd: grey.pgm: a PGM picture: phones' browsers show PNG, " +
              'JPEG and WebP';
  if (!warnings.includes(pgm)) fail(`the core did not warn "${pgm}": ${warnings}`);

  for (const o of models) {
    const mesh = core.sceneMesh(o.solid.mesh);
    if (mesh.error) { fail(`mesh ${o.solid.mesh}: ${mesh.error}`); continue; }
    const part = mesh.parts[0];
    if (mesh.source === 'models/png.obj') {
      if (mesh.pictures.length !== 1 || part.picture !== 0) fail('png.obj: its picture did not reach the page');
      else if (!mesh.pictures[0].equals(png)) fail('png.obj: the picture\'s bytes are not the PNG file\'s');
    } else if (mesh.source === 'models/grey.obj') {
      if (mesh.pictures.length !== 0 || part.picture !== -1) fail('grey.obj: a picture phones cannot show was sent');
      const c = part.colour.map((v) => v.toFixed(2)).join(' ');
      if (c !== '0.20 0.40 0.60 1.00') fail(`grey.obj: drawn in ${c}, not its colour Kd 0.2 0.4 0.6`);
    } else fail(`a mesh of ${mesh.source}`);
  }
  console.log(`${models.length} models drawn; the core said:\n${errors}\n${warnings}`);
} catch (e) {
  fail(e.message);
} finally {
  fs.rmSync(tmp, { recursive: true, force: true });
}
if (failures.length) {
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(1);
}
