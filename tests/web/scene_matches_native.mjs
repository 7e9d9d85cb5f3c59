// The WebAssembly core runs a scene as the desktop does: the museum example's Lua, on frames of the synthetic
// source, places each picture and video in the core where `arwb render --overlays` places it on the same frames
// (the same markers, kinds and sources, quads to 1e-6 px), with the videos' clocks and the text cards' layouts, of the
// desktop's sizes. A hostile scene meets the desktop's limits in the core: a
// runaway callback is stopped and disabled with the desktop's words, and the next frames go on. Run by ctest as
//   node --no-experimental-fetch scene_matches_native.mjs ARWB CORE_JS
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { loadCore, readPng } from './web_support.mjs';

const [arwb, coreJs] = process.argv.slice(2);
const failures = [];
const fail = (message) => failures.push(message);
const run = (cmd, args) => execFileSync(cmd, args, { encoding: 'utf8', maxBuffer: 1 << 26,
                                                    stdio: ['ignore', 'pipe', 'pipe'] });
const source = path.resolve(path.dirname(new URL(import.meta.url).pathname), '../../scripts/museum');

// Every file under a folder, as paths relative to it.
function filesUnder(dir, rel = '') {
  return fs.readdirSync(path.join(dir, rel), { withFileTypes: true }).flatMap((e) =>
    e.isDirectory() ? filesUnder(dir, path.join(rel, e.name)) : [path.join(rel, e.name)]);
}

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-scene-'));
try {
  // The synthetic source's frames (ids 0, 1 and 2 moving about), as a folder of PNGs: rendered through an empty
  // scene, which draws nothing over them.
  const empty = path.join(tmp, 'empty.lua');
  fs.writeFileSync(empty, 'dictionary "ARUCO_ORIGINAL"\n');
  const frames = path.join(tmp, 'frames');
  run(arwb, ['render', '--scene', empty, '--input', 'synthetic', '--frames', '24', '--out', frames]);
  const overlaysFile = path.join(tmp, 'overlays.jsonl');
  run(arwb, ['render', '--scene', path.join(source, 'museum.lua'), '--input', frames, '--out', path.join(tmp, 'out'),
             '--overlays', overlaysFile]);
  const native = fs.readFileSync(overlaysFile, 'utf8').trim().split('\n').map((l) => JSON.parse(l));

  const core = await loadCore(coreJs, { video: true });   // as render searches the frames: a video
  for (const f of filesUnder(source)) core.writeFile(`/bundle/scene/${f}`, fs.readFileSync(path.join(source, f)));
  // The video's size and length as a browser reads them, here from ffprobe.
  const probe = JSON.parse(run('ffprobe', ['-v', 'error', '-select_streams', 'v:0', '-show_entries',
                                           'stream=width,height:format=duration', '-of', 'json',
                                           path.join(source, 'media/orbit.mp4')]));
  core.sceneVideo('/bundle/scene/media/orbit.mp4', probe.streams[0].width, probe.streams[0].height,
                  Number(probe.format.duration));
  const loaded = core.sceneLoad('/bundle/scene/museum.lua');
  if (!loaded.ok) throw new Error(`the museum did not load in the core: ${loaded.error}`);
  if (loaded.dictionary !== 'ARUCO_ORIGINAL') fail(`dictionary ${loaded.dictionary}`);

  const tally = { frames: 0, placed: 0, texts: 0, videos: 0, worst: 0 };
  for (const want of native) {
    const name = `frame ${want.frame}`;
    const png = path.join(frames, `frame_${String(want.frame).padStart(6, '0')}.png`);
    const det = core.detect(readPng(png));
    if (det.error) { fail(`${name}: ${det.error}`); continue; }
    const got = core.sceneStep(want.t);
    if (got.errors.length) fail(`${name}: the scene said ${got.errors.join('; ')}`);
    tally.frames++;
    const key = (o) => `${o.marker}/${o.kind}/${o.source}`;
    const g = got.overlays.map(key).join(' '), w = want.overlays.map(key).join(' ');
    if (g !== w) { fail(`${name}: overlays ${g || '(none)'}, native ${w || '(none)'}`); continue; }
    want.overlays.forEach((wo, i) => {
      const go = got.overlays[i];
      if (wo.kind === 'text') {   // laid out by the desktop's card layout in the core, drawn by the page
        tally.texts++;
        if (go.text !== wo.text) fail(`${name}: marker ${wo.marker}'s text "${go.text}", native "${wo.text}"`);
        if (!go.card || go.card.lines.join('\n') !== wo.text || go.card.width !== wo.size[0])
          fail(`${name}: marker ${wo.marker}'s card ${JSON.stringify(go.card)}, native ${wo.size}`);
      }
      if (JSON.stringify(go.size) !== JSON.stringify(wo.size))
        fail(`${name}: ${key(wo)} is ${go.size}, native ${wo.size}`);
      const d = Math.max(...wo.quad.corners.flatMap((c, k) => c.map((v, a) => Math.abs(v - go.quad.corners[k][a]))));
      tally.worst = Math.max(tally.worst, d);
      tally.placed++;
      if (!(d < 1e-6)) fail(`${name}: ${key(wo)} placed ${d.toExponential(2)} px from native`);
      if (wo.kind === 'video') {
        tally.videos++;
        if (!go.video || !go.video.loop || !go.video.playing || !(go.video.duration > 0))
          fail(`${name}: the video's clock ${JSON.stringify(go.video)}`);
      }
    });
  }
  if (tally.placed < 20 || tally.videos < 3 || tally.texts < 10)
    fail(`too little compared: ${JSON.stringify(tally)}`);

  // The bundle's self-test in the core gives export's rows (manifest.json's): the same ids, lines and media, each
  // fired. A mapping whose callback fails does not fire, in the core as at export, with the scene's words.
  run(arwb, ['export', '--scene', path.join(source, 'museum.lua'), '--out', path.join(tmp, 'bundle'), '--quiet']);
  const exported = JSON.parse(fs.readFileSync(path.join(tmp, 'bundle', 'manifest.json'), 'utf8')).self_test;
  const tested = core.sceneSelfTest('/bundle/scene/museum.lua');
  const row = (r) => `${r.id}/${r.line}/${r.media}/${r.fired}`;
  if (!tested.passed || tested.rows.map(row).join(' ') !== exported.map(row).join(' '))
    fail(`the core's self-test ${tested.rows.map(row).join(' ')} (${tested.error}), export's ` +
         `${exported.map(row).join(' ')}`);
  const broken = 'marker(0, { media = text "fine" })\n' +
                 'marker(1, { media = text "x", on_enter = function(m) error("broken exhibit") end })\n';
  fs.mkdirSync(path.join(tmp, 'broken'));
  fs.writeFileSync(path.join(tmp, 'broken', 'scene.lua'), broken);
  core.writeFile('/bundle/broken/scene.lua', broken);
  const brokenTest = core.sceneSelfTest('/bundle/broken/scene.lua');
  let refused = '';
  try {
    run(arwb, ['export', '--scene', path.join(tmp, 'broken', 'scene.lua'), '--out', path.join(tmp, 'b2'), '--quiet']);
  } catch (e) {
    refused = String(e.stderr);
  }
  const failed = brokenTest.rows.filter((r) => !r.fired);
  // The same words after the scene's folder, which differs (the core's file system, the test's folder).
  const words = failed.length ? failed[0].detail.slice(failed[0].detail.lastIndexOf('scene.lua:')) : '?';
  if (brokenTest.passed || failed.length !== 1 || failed[0].id !== 1 || !words.includes('broken exhibit') ||
      !refused.includes(`marker 1 does not fire its mapping in the self-test: ${path.join(tmp, 'broken')}/${words}`))
    fail(`a failing callback: the core's self-test ${JSON.stringify(brokenTest)}; export said "${refused}"`);

  // A hostile scene: a callback that never returns is stopped by the desktop's limits and disabled; the frames
  // after it still run the scene (marker 1's text stays).
  core.writeFile('/bundle/hostile/scene.lua', 'marker(0, { on_update = function(m) while true do end end })\n' +
                                              'marker(1, { media = text "still here" })\n');
  const hostile = core.sceneLoad('/bundle/hostile/scene.lua');
  if (!hostile.ok) throw new Error(`the hostile scene did not load: ${hostile.error}`);
  const first = path.join(frames, 'frame_000000.png');
  const t0 = Date.now();
  let said = '';
  let still = 0;
  for (let i = 0; i < 4; ++i) {
    core.detect(readPng(first));
    const r = core.sceneStep(100 + i * 0.05);
    said += r.errors.join('\n');
    still += r.overlays.filter((o) => o.text === 'still here').length;
  }
  const ms = Date.now() - t0;
  if (!said.includes('scene.lua:1: instruction budget of 5000000 exceeded in on_update of marker 0; disabled') &&
      !said.includes('scene.lua:1: ran longer than 250 ms in on_update of marker 0; disabled'))
    fail(`the runaway callback was not stopped as on the desktop: "${said}"`);
  if (still !== 4) fail(`marker 1's text was drawn on ${still} of 4 frames after the runaway callback`);
  console.log(`${tally.frames} frames: ${tally.placed} media placed as arwb render places them (to ` +
              `${tally.worst.toExponential(2)} px), ${tally.videos} videos with their clock, ${tally.texts} of ` +
              'them text cards laid out at the desktop\'s size; ' +
              `a runaway callback stopped and disabled in ${ms} ms over 4 frames; the self-test's ` +
              `${tested.rows.length} rows as export's, and "${words}" for a failing ` +
              'callback');
} catch (e) {
  fail(e.stack || String(e));
} finally {
  fs.rmSync(tmp, { recursive: true, force: true });
}
if (failures.length) {
  console.error(failures.slice(0, 30).join('\n'));
  process.exit(1);
}
