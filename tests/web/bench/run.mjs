// The web bench: in one headless Chromium page, on the same synthetic photographs, our WebAssembly core, opencv.js's
// ArucoDetector (npm's @techstark/opencv-js) and js-aruco2, each frame run --reps times; beside them native
// `arwb bench` (arwb alone) on the same frames. Prints each one's median ms per frame and recall, and our core's
// time as a ratio of each. Figures, not a test: run by hand or by docs/benchmarks.md.
//   node --no-experimental-fetch tests/web/bench/run.mjs ARWB CORE_JS [--count N] [--size WxH] [--reps R]
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Chromium } from '../chromium_support.mjs';
import { serve } from '../web_support.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args.splice(i, 2)[1] : fallback;
};
const count = option('--count', '30'), size = option('--size', '1280x720'), reps = option('--reps', '5');
const [arwb, coreJs] = args;
if (!arwb || !coreJs) {
  console.error('usage: run.mjs ARWB CORE_JS [--count N] [--size WxH] [--reps R]');
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const modules = path.resolve(here, '../../../web/node_modules');
for (const need of ['@techstark/opencv-js/dist/opencv.js', 'js-aruco2/src/aruco.js'])
  if (!fs.existsSync(path.join(modules, need))) {
    console.error(`run.mjs: ${path.join(modules, need)} is missing: third_party/setup installs web/'s npm packages`);
    process.exit(2);
  }

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-bench-'));
let browser = null, server = null, status = 0;
try {
  const site = path.join(tmp, 'site');
  fs.mkdirSync(site);
  execFileSync(arwb, ['synth', '--out', path.join(site, 'frames'), '--count', count, '--size', size, '--seed', '3'],
               { stdio: 'pipe' });
  const link = (from, name) => fs.symlinkSync(path.resolve(from), path.join(site, name));
  link(path.join(here, 'bench.html'), 'bench.html');
  link(path.join(here, 'bench.js'), 'bench.js');
  link(coreJs, 'arwb_core.js');
  link(coreJs.replace(/\.js$/, '.wasm'), 'arwb_core.wasm');
  link(path.join(modules, '@techstark/opencv-js/dist/opencv.js'), 'opencv.js');
  link(path.join(modules, 'js-aruco2/src'), 'js-aruco2');

  const native = JSON.parse(execFileSync(arwb, ['bench', path.join(site, 'frames'), '--peers', 'none', '--reps', reps,
                                                '--json'], { encoding: 'utf8' }));
  const nativeRow = native.rows.find((r) => r.resolution === 'all');

  server = await serve([site], { isolated: true });
  browser = await Chromium.launch();
  const page = await browser.newPage(`${server.url}bench.html?repeats=${reps}`,
                                     { width: 800, height: 600, mobile: false });
  const result = await page.waitFor('window.benchResult', 600);
  if (result.error) throw new Error(`the bench page failed: ${result.error}`);

  const ours = result.detectors['arwb (WebAssembly)'];
  const rows = [['arwb (native, ' + native.vector_code + ')', nativeRow.median_ms, nativeRow.recall],
                ...Object.entries(result.detectors).map(([name, d]) => [name, d.median_ms, d.recall])];
  console.log(`${result.frames} frames of ${size} (arwb synth, seed 3), fastest of ${reps} runs per frame, one ` +
              `thread; the page in headless Chromium ${browser.version}, native on ${native.cpu}`);
  console.log('detector'.padEnd(34) + 'median ms'.padStart(10) + 'recall'.padStart(9) + '   arwb (WebAssembly) is');
  for (const [name, ms, recall] of rows) {
    const ratio = name.startsWith('arwb (WebAssembly)') ? '' : ms >= ours.median_ms
      ? `${(ms / ours.median_ms).toFixed(2)}x faster` : `${(ours.median_ms / ms).toFixed(2)}x slower`;
    console.log(name.padEnd(34) + ms.toFixed(2).padStart(10) + recall.toFixed(3).padStart(9) + `   ${ratio}`);
  }
  if (!result.isolated)
    console.log('note: the page was not cross-origin isolated, so its clock ticks in tenths of a millisecond: the ' +
                'page\'s times and ratios are that coarse');
} catch (e) {
  console.error(`run.mjs: ${e.message}`);
  status = 1;
} finally {
  if (browser) await browser.close();
  if (server) server.close();
  fs.rmSync(tmp, { recursive: true, force: true });
}
process.exit(status);
