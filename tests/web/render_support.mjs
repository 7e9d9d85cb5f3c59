// What the page-against-`arwb render` tests share: a scene exported with --web and opened in headless Chromium
// whose fake camera holds one synthetic frame showing markers 0, 1 and 2; the page's composite of a searched frame
// (the frame with its media layer over it) against `arwb render` of the same pixels, with the same calibration or
// none. Where either drew, the two agree but for the media's edges.
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { Chromium } from './chromium_support.mjs';
import { arwbServe, readPng, writeY4m } from './web_support.mjs';

// A pixel differs when a channel is this far off (the media's edges are anti-aliased differently by the desktop's
// MSAA and the browser's); the page and the desktop agree when at most this share of the drawn pixels differ.
export const kChannel = 48, kMaxDiffering = 0.03;

// scene: the scene file (its folder is exported); calib: a calibration file or ''; kinds: the overlay kinds the page
// must have drawn before its composite is taken; tmp: a folder for the frames, the bundle and the pictures;
// then(page): more of the test, on the page still showing the frame.
// Returns {camera, drawnPx, differing, share, composite, native, errors, exceptions, then: then's}.
export async function pageAgainstRender({ arwb, tmp, scene, calib, kinds, then = async () => null }) {
  const run = (args) => execFileSync(arwb, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
  const ids = [0, 1, 2];
  // A synthetic frame with markers 0, 1 and 2, held in front of the fake camera.
  const frames = path.join(tmp, 'frames');
  const empty = path.join(tmp, 'empty.lua');
  fs.writeFileSync(empty, 'dictionary "ARUCO_ORIGINAL"\n');
  run(['render', '--scene', empty, '--input', 'synthetic', '--frames', '8', '--out', frames]);
  const found = run(['detect', '--json', frames]).trim().split('\n').map((l) => JSON.parse(l));
  const all = found.find((r) => ids.every((id) => r.markers.some((m) => m.id === id)));
  if (!all) throw new Error('no synthetic frame shows markers 0, 1 and 2');
  const y4m = path.join(tmp, 'camera.y4m');
  writeY4m(y4m, Array(8).fill(readPng(all.source)), 4);

  const bundle = path.join(tmp, 'bundle');
  const withCalib = calib ? ['--calib', calib] : [];
  run(['export', '--scene', scene, ...withCalib, '--out', bundle, '--web', '--quiet']);
  const server = await arwbServe(arwb, bundle);
  let browser = null;
  try {
    browser = await Chromium.launch({ args: ['--use-fake-device-for-media-stream', '--use-fake-ui-for-media-stream',
                                             `--use-file-for-fake-video-capture=${y4m}`] });
    const page = await browser.newPage(server.url);
    const state = await page.waitFor('window.arwbPlayer && arwbPlayer.state !== "checking" && arwbPlayer.state', 20);
    if (state !== 'ready') throw new Error(`the first screen says ${state}`);
    await page.evaluate('arwbPlayer.setParam("full_search_interval", 1)');
    await page.evaluate('document.getElementById("start").click()');
    await page.waitFor('arwbPlayer.state === "running" || arwbPlayer.state === "failed"', 20);
    const camera = await page.waitFor(`arwbPlayer.camera.startsWith("${calib ? 'calibrated' : 'assumed'}") && ` +
                                      'arwbPlayer.camera', 20);
    // Once every kind has been drawn (pictures loaded), the composite of a searched frame with all three markers.
    let shot = null;
    for (const end = Date.now() + 60000; !shot && Date.now() < end;) {
      const drawn = await page.evaluate('arwbPlayer.scene.drawn');
      if (kinds.every((k) => drawn.includes(k))) {
        await new Promise((r) => setTimeout(r, 500));   // the pictures' textures, made on first use
        const c = await page.evaluate('arwbPlayer.composite()');
        if (c && ids.every((id) => c.result.markers.some((m) => m.id === id))) shot = c;
      }
      await new Promise((r) => setTimeout(r, 200));
    }
    if (!shot) throw new Error(`the page did not draw every kind of ${kinds.join(', ')} in 60 s (${camera})`);
    const grabbed = path.join(tmp, 'grabbed.png');
    const composite = path.join(tmp, 'page.png');
    fs.writeFileSync(grabbed, Buffer.from(shot.frame.split(',')[1], 'base64'));
    fs.writeFileSync(composite, Buffer.from(shot.png.split(',')[1], 'base64'));
    const nativeDir = path.join(tmp, 'native');
    run(['render', '--scene', scene, ...withCalib, '--input', grabbed, '--out', nativeDir]);
    const native = path.join(nativeDir, 'frame_000000.png');
    const want = readPng(native), got = readPng(composite), base = readPng(grabbed);
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
    const more = await then(page);
    return { camera, drawnPx, differing, share: differing / Math.max(drawnPx, 1), composite, native,
             errors: await page.evaluate('arwbPlayer.errors'), exceptions: page.exceptions, then: more };
  } finally {
    if (browser) await browser.close();
    await server.close();
  }
}

// The figures a test prints and the failures it finds: too little drawn, too much differing, errors, exceptions.
export function judge(r, minDrawn, fail) {
  if (r.drawnPx < minDrawn) fail(`only ${r.drawnPx} pixels were drawn over the frame`);
  if (r.share > kMaxDiffering)
    fail(`${r.differing} of the ${r.drawnPx} drawn pixels differ from arwb render's ` +
         `(${(100 * r.share).toFixed(2)} %); kept in ${r.composite} and ${r.native}`);
  if (r.errors.length) fail(`the page reported: ${r.errors.join('; ')}`);
  if (r.exceptions.length) fail(`the page threw: ${r.exceptions.join('; ')}`);
  console.log(`camera ${r.camera}; ${r.drawnPx} pixels drawn over the frame by the page or arwb render, ` +
              `${r.differing} of them (${(100 * r.share).toFixed(2)} %) differ by more than ${kChannel}`);
}

// A test's frame: body(tmp, fail) in a new folder (removed when nothing failed: a failure's pictures are kept), its
// failures printed and the process's exit status 1 when there are any.
export async function comparisonTest(prefix, body) {
  const failures = [];
  const fail = (message) => failures.push(message);
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), prefix));
  try {
    await body(tmp, fail);
  } catch (e) {
    fail(e.message);
  } finally {
    if (!failures.length) fs.rmSync(tmp, { recursive: true, force: true });
  }
  if (failures.length) {
    for (const f of failures) console.error(`FAIL: ${f}`);
    process.exit(1);
  }
}
