// The player's page of a bundle exported with --web (the museum scene), served by `arwb serve` and opened in headless
// Chromium with a fake camera playing synthetic photographs: its files checked and kept for offline use by its
// service worker, it finds in each frame it searched what `arwb detect` finds in the same pixels (ids and corners
// within 1e-3 px), in its worker, asking nothing of any origin but its own. Run by ctest as
//   node --no-experimental-fetch page_matches_native.mjs ARWB CORE_JS
// ARWB_WEB_SCREENSHOT=FILE saves the page at a phone's size (390x844) once it has found markers.
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Chromium } from './chromium_support.mjs';
import { arwbServe, compareWithNative, readPng, tallyProblems, writeY4m } from './web_support.mjs';

const [arwb] = process.argv.slice(2);   // the core comes with the bundle (arwb export --web)
const scene = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../scripts/museum/museum.lua');
const failures = [];
const fail = (message) => failures.push(message);
const grabsWanted = 6;

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-page-'));
let browser = null, server = null;
try {
  const frames = path.join(tmp, 'frames');
  execFileSync(arwb, ['synth', '--out', frames, '--count', '8', '--seed', '5', '--size', '640x480'], { stdio: 'pipe' });
  // Then the synthetic source's markers 0, 1 and 2 (the museum's), through an empty scene that draws nothing.
  const empty = path.join(tmp, 'empty.lua');
  fs.writeFileSync(empty, 'dictionary "ARUCO_ORIGINAL"\n');
  execFileSync(arwb, ['render', '--scene', empty, '--input', 'synthetic', '--frames', '8', '--out', frames],
               { stdio: 'pipe' });
  const pngs = fs.readdirSync(frames).filter((f) => f.endsWith('.png')).sort();
  const y4m = path.join(tmp, 'camera.y4m');
  // The museum's frames held a second each (four frames at 4 fps), as a hand holds a camera still.
  writeY4m(y4m, pngs.flatMap((f) => Array(f.startsWith('frame_') ? 4 : 1).fill(readPng(path.join(frames, f)))), 4);

  const bundle = path.join(tmp, 'bundle');
  execFileSync(arwb, ['export', '--scene', scene, '--out', bundle, '--web', '--quiet'], { stdio: 'pipe' });
  server = await arwbServe(arwb, bundle);
  browser = await Chromium.launch({ args: ['--use-fake-device-for-media-stream', '--use-fake-ui-for-media-stream',
                                           `--use-file-for-fake-video-capture=${y4m}`,
                                           '--host-resolver-rules=MAP phone.test 127.0.0.1'] });
  // Over plain HTTP from another host the page is not a secure context: it says how to fix that and keeps Start off.
  const insecure = await browser.newPage(server.url.replace('127.0.0.1', 'phone.test'));
  await insecure.waitFor('window.arwbPlayer && arwbPlayer.state !== "checking"', 20);
  const advice = await insecure.evaluate('[arwbPlayer.state, document.getElementById("advice").innerText, ' +
                                         'document.getElementById("start").disabled]');
  if (advice[0] !== 'blocked' || !advice[1].startsWith('Open this page over HTTPS') || advice[2] !== true)
    fail(`over plain HTTP the first screen said ${JSON.stringify(advice)}`);
  const page = await browser.newPage(server.url);
  const state = await page.waitFor('window.arwbPlayer && arwbPlayer.state !== "checking" && arwbPlayer.state', 20);
  const text = (id) => page.evaluate(`document.getElementById("${id}").innerText`);
  if (state !== 'ready') throw new Error(`the first screen says ${state}: ${await text('checks')} ${await text('bundle')}`);
  const kept = await page.evaluate('[arwbPlayer.bundle.state, arwbPlayer.bundle.offline]');
  if (kept[0] !== 'verified' || kept[1] !== true)
    fail(`the bundle was ${kept[0]}, ${kept[1] ? '' : 'not '}kept for offline use: ${await text('bundle')}`);
  // The bundle's self-test, run again by the page's core before the camera starts, passes as it did at export and
  // says so on the first screen. It comes after the worker has fetched the scene's media through the service worker:
  // 0.3 s alone, and more than 20 s once on CI beside two other Chromium tests; 60 s is a hang.
  const selfTest = await page.waitFor('arwbPlayer.selfTest', 60);
  const rows = await page.evaluate('arwbPlayer.bundle.manifest.self_test.length');
  if (!selfTest.passed || selfTest.rows.length !== rows || !(await text('selftest')).includes(selfTest.text))
    fail(`the page's self-test: ${selfTest.text} (${selfTest.rows.length} rows, the manifest's ${rows}); the first ` +
         `screen says "${await text('selftest')}"`);
  // Each frame searched whole, as `arwb detect` searches the grabbed stills (the page's video mode searches around
  // the last frame's markers, as the workbench's live view does).
  await page.evaluate('arwbPlayer.setParam("full_search_interval", 1)');
  await page.evaluate('document.getElementById("start").click()');
  await page.waitFor('arwbPlayer.state === "running" || arwbPlayer.state === "failed"', 20);
  const started = await page.evaluate('arwbPlayer.state');
  if (started !== 'running') throw new Error(`Start failed: ${await text('advice')}`);

  // Frames the worker searched, each with what it found, until six differ (the camera loops over the
  // sixteen pictures).
  const grabs = new Map();
  const until = Date.now() + 120000;
  let shot = false;
  if (process.env.ARWB_WEB_SCREENSHOT) await page.evaluate('document.getElementById("overlay").hidden = false');
  const drawnKinds = new Set();   // the kinds of media the page drew over the camera view
  while (grabs.size < grabsWanted && Date.now() < until) {
    const g = await page.evaluate('arwbPlayer.grab()');
    const kinds = await page.evaluate('arwbPlayer.scene.drawn');
    kinds.forEach((k) => drawnKinds.add(k));
    if (g && !grabs.has(g.png)) grabs.set(g.png, g.result);
    // The screenshot: when the museum's markers are all in the newest search and all its kinds of media drawn.
    const ids = await page.evaluate('arwbPlayer.markers.map((m) => m.id)');
    if (!shot && process.env.ARWB_WEB_SCREENSHOT && ['image', 'video', 'text'].every((k) => kinds.includes(k)) &&
        [0, 1, 2].every((id) => ids.includes(id))) {
      await page.screenshot(process.env.ARWB_WEB_SCREENSHOT);
      shot = true;
    }
    await new Promise((r) => setTimeout(r, 150));
  }
  if (grabs.size < grabsWanted) fail(`the page searched only ${grabs.size} distinct frames in 120 s`);
  // The film shows once marker 2 is in view and its first frame decoded.
  for (const end = Date.now() + 30000; !drawnKinds.has('video') && Date.now() < end;) {
    (await page.evaluate('arwbPlayer.scene.drawn')).forEach((k) => drawnKinds.add(k));
    await new Promise((r) => setTimeout(r, 100));
  }

  const grabbed = path.join(tmp, 'grabbed');
  fs.mkdirSync(grabbed);
  const results = [...grabs.entries()];
  results.forEach(([png], i) => fs.writeFileSync(path.join(grabbed, `frame_${i}.png`),
                                                 Buffer.from(png.split(',')[1], 'base64')));
  const native = execFileSync(arwb, ['detect', '--json', grabbed], 
                              { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] })
    .trim().split('\n').map((line) => JSON.parse(line));
  const tally = { markers: 0, worst: 0 };
  for (const want of native) {
    const i = Number(path.basename(want.source).match(/frame_(\d+)/)[1]);
    const problem = compareWithNative(`frame ${i}`, results[i][1], want, tally);
    if (problem) fail(problem);
  }
  tallyProblems(tally).forEach(fail);
  // The museum has no calibration: every marker's pose with the default camera, its axes to draw.
  const camera = await page.evaluate('arwbPlayer.camera');
  if (!camera.startsWith('assumed')) fail(`the page's camera is "${camera}"`);
  for (const [, result] of results)
    for (const m of result.markers)
      if (!m.pose || m.pose.camera !== 'assumed' || m.pose.axes.length !== 4) fail(`marker ${m.id} has no pose to draw`);

  // Object URLs of the page's own Blobs (its videos) are this origin's too: nothing goes over the network.
  const foreign = page.requests.filter((u) => !u.startsWith(server.url) && !u.startsWith('data:') &&
                                              !u.startsWith(`blob:${server.url.replace(/\/$/, '')}`));
  const other = server.url.replace('127.0.0.1', 'phone.test');
  foreign.push(...insecure.requests.filter((u) => !u.startsWith(other)));
  if (foreign.length) fail(`the page asked for ${foreign.join(', ')}`);
  // The museum's scene runs in the worker: its pictures, film and captions drawn on and beside their markers.
  const ran = await page.evaluate('({status: arwbPlayer.scene.status, notes: arwbPlayer.notes, ' +
                                  'line: arwbPlayer.scene.line()})');
  if (!ran.status || !ran.status.ok) fail(`the scene did not run: ${JSON.stringify(ran.status)}`);
  if (!drawnKinds.has('image') || !drawnKinds.has('video') || !drawnKinds.has('text'))
    fail(`the page drew ${[...drawnKinds].join(', ') || 'no media'} (its overlay: scene: ${ran.line}) `);
  if (ran.notes.length) fail(`the page says it does not draw: ${ran.notes.join('; ')}`);
  const errors = await page.evaluate('arwbPlayer.errors');
  if (errors.length) fail(`the page reported: ${errors.join('; ')}`);
  if (page.exceptions.length) fail(`the page threw: ${page.exceptions.join('; ')}`);
  const stats = await page.evaluate('({drawn: arwbPlayer.drawn, detected: arwbPlayer.detected, ' +
                                    'ms: [...arwbPlayer.detectMs].sort((a, b) => a - b)})');
  const median = stats.ms.length ? stats.ms[Math.floor(stats.ms.length / 2)] : NaN;
  console.log(`${grabs.size} frames searched in the page's worker, ${tally.markers} markers, the same ids as arwb ` +
              `detect; corners differ by up to ${tally.worst.toFixed(6)} px; ${stats.drawn} frames drawn, ` +
              `${stats.detected} searched, median ${median.toFixed(2)} ms; ` +
              `media drawn: ${[...drawnKinds].join(', ')}; self-test: ${selfTest.text}; ` +
              `${server.served.length} requests, ` +
              `all to 127.0.0.1`);
} catch (e) {
  fail(e.message);
} finally {
  if (browser) await browser.close();
  if (server) await server.close();
  fs.rmSync(tmp, { recursive: true, force: true });
}
if (failures.length) {
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(1);
}
