// The scene's solids on the phone, against `arwb render`: a bundle with a calibration (so that flat media are drawn
// through the lens model too) and a scene of a cube with a picture on its top face on marker 0, the axes and a text
// card on marker 1 and a picture on marker 2, exported with --web and opened in headless Chromium whose fake camera holds one
// synthetic frame. The page's composite of a searched frame (the frame with its media layer over it) is compared
// with `arwb render` of the same pixels with the same calibration: where either drew, the two agree but for the
// media's edges. Run by ctest as
//   node --no-experimental-fetch solids_match_render.mjs ARWB CORE_JS
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Chromium } from './chromium_support.mjs';
import { arwbServe, readPng, writeY4m } from './web_support.mjs';

const [arwb] = process.argv.slice(2);
const museum = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../scripts/museum');
const failures = [];
const fail = (message) => failures.push(message);
const run = (args) => execFileSync(arwb, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
// A pixel differs when a channel is this far off (the media's edges are anti-aliased differently by the desktop's
// MSAA and the browser's); the page and the desktop agree when at most this share of the drawn pixels differ.
const kChannel = 48, kMaxDiffering = 0.03;

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-solids-'));
let browser = null, server = null;
try {
  // The scene, beside the museum's pictures.
  const sceneDir = path.join(tmp, 'scene');
  fs.cpSync(path.join(museum, 'media'), path.join(sceneDir, 'media'), { recursive: true });
  const scene = path.join(sceneDir, 'solids.lua');
  fs.writeFileSync(scene, [
    'dictionary "ARUCO_ORIGINAL"',
    'marker(0, { media = cube { colour = "#46b4eb", faces = { top = "media/composition.png", front = "#e05050" } } })',
    'marker(1, { media = axes { length = 1.4 } })',
    'marker(2, { media = image "media/sunset.png", place = on_marker { scale = 1.2 } })',
    // A card on a light half-clear background, laid over the frame as the desktop lays it (premultiplied).
    'marker(1, { media = text("axes", { size = 28, colour = "#202020", background = "#f0f0f080" }),',
    '            place = beside { side = "bottom", gap = 0.1, size = 0.45 } })',
    ''].join('\n'));
  // A calibration with lens distortion, of the synthetic frames' size.
  run(['synth', '--chessboard', '--out', path.join(tmp, 'views'), '--count', '1']);
  const calib = path.join(tmp, 'views', 'truth_camera.yml');
  // A synthetic frame with markers 0, 1 and 2, held in front of the fake camera.
  const frames = path.join(tmp, 'frames');
  const empty = path.join(tmp, 'empty.lua');
  fs.writeFileSync(empty, 'dictionary "ARUCO_ORIGINAL"\n');
  run(['render', '--scene', empty, '--input', 'synthetic', '--frames', '8', '--out', frames]);
  const found = run(['detect', '--json', frames]).trim().split('\n').map((l) => JSON.parse(l));
  const all = found.find((r) => [0, 1, 2].every((id) => r.markers.some((m) => m.id === id)));
  if (!all) throw new Error('no synthetic frame shows markers 0, 1 and 2');
  const still = readPng(all.source);
  const y4m = path.join(tmp, 'camera.y4m');
  writeY4m(y4m, Array(8).fill(still), 4);

  const bundle = path.join(tmp, 'bundle');
  run(['export', '--scene', scene, '--calib', calib, '--out', bundle, '--web', '--quiet']);
  server = await arwbServe(arwb, bundle);
  browser = await Chromium.launch({ args: ['--use-fake-device-for-media-stream', '--use-fake-ui-for-media-stream',
                                           `--use-file-for-fake-video-capture=${y4m}`] });
  const page = await browser.newPage(server.url);
  const state = await page.waitFor('window.arwbPlayer && arwbPlayer.state !== "checking" && arwbPlayer.state', 20);
  if (state !== 'ready') throw new Error(`the first screen says ${state}`);
  await page.evaluate('arwbPlayer.setParam("full_search_interval", 1)');
  await page.evaluate('document.getElementById("start").click()');
  await page.waitFor('arwbPlayer.state === "running" || arwbPlayer.state === "failed"', 20);
  const camera = await page.waitFor('arwbPlayer.camera.startsWith("calibrated") && arwbPlayer.camera', 20);
  // Once every medium has been drawn (the cube's face picture and the sunset loaded), the composite of a searched
  // frame in which all three markers were found.
  let shot = null;
  for (const end = Date.now() + 60000; !shot && Date.now() < end;) {
    const drawn = await page.evaluate('arwbPlayer.scene.drawn');
    if (['cube', 'axes', 'image', 'text'].every((k) => drawn.includes(k))) {
      await new Promise((r) => setTimeout(r, 500));   // the pictures' textures, made on first use
      const c = await page.evaluate('arwbPlayer.composite()');
      if (c && [0, 1, 2].every((id) => c.result.markers.some((m) => m.id === id))) shot = c;
    }
    await new Promise((r) => setTimeout(r, 200));
  }
  if (!shot) throw new Error(`the page did not draw the cube, the axes, the card and the picture in 60 s (${camera})`);
  const grabbed = path.join(tmp, 'grabbed.png');
  const composite = path.join(tmp, 'page.png');
  fs.writeFileSync(grabbed, Buffer.from(shot.frame.split(',')[1], 'base64'));
  fs.writeFileSync(composite, Buffer.from(shot.png.split(',')[1], 'base64'));
  const native = path.join(tmp, 'native');
  run(['render', '--scene', scene, '--calib', calib, '--input', grabbed, '--out', native]);
  const want = readPng(path.join(native, 'frame_000000.png'));
  const got = readPng(composite), base = readPng(grabbed);
  if (got.width !== want.width || got.height !== want.height)
    throw new Error(`the page's composite is ${got.width}x${got.height}, arwb render's ${want.width}x${want.height}`);
  // Where either drew (its pixel is not the camera's), and of those, where the two differ.
  let drawnPx = 0, differing = 0;
  const off = (a, b, i) => Math.max(...[0, 1, 2].map((c) => Math.abs(a[i + c] - b[i + c])));
  for (let i = 0; i < want.data.length; i += 4) {
    if (off(want.data, base.data, i) <= kChannel && off(got.data, base.data, i) <= kChannel) continue;
    ++drawnPx;
    if (off(want.data, got.data, i) > kChannel) ++differing;
  }
  const share = differing / Math.max(drawnPx, 1);
  if (drawnPx < 2000) fail(`only ${drawnPx} pixels were drawn over the frame`);
  if (share > kMaxDiffering)
    fail(`${differing} of the ${drawnPx} drawn pixels differ from arwb render's (${(100 * share).toFixed(2)} %); ` +
         `kept in ${composite} and ${path.join(native, 'frame_000000.png')}`);
  const errors = await page.evaluate('arwbPlayer.errors');
  if (errors.length) fail(`the page reported: ${errors.join('; ')}`);
  if (page.exceptions.length) fail(`the page threw: ${page.exceptions.join('; ')}`);
  console.log(`camera ${camera}; ${drawnPx} pixels drawn over the frame by the page or arwb render, ` +
              `${differing} of them (${(100 * share).toFixed(2)} %) differ by more than ${kChannel}`);
} catch (e) {
  fail(e.message);
} finally {
  if (browser) await browser.close();
  if (server) await server.close();
  if (!failures.length) fs.rmSync(tmp, { recursive: true, force: true });   // a failure's pictures are kept
}
if (failures.length) {
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(1);
}
