// A bundle exported with --web whose files were changed after export: its page, opened in headless Chromium (on
// 127.0.0.1, a secure context), refuses to start and names the first file that differs, as `arwb play` does; the
// untouched bundle beside it starts. Run by ctest as
//   node --no-experimental-fetch bundle_refuses_changed_files.mjs ARWB CORE_JS
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Chromium } from './chromium_support.mjs';
import { serve } from './web_support.mjs';

const [arwb] = process.argv.slice(2);
const scene = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../scripts/museum/museum.lua');
const failures = [];
const fail = (message) => failures.push(message);

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-bundle-page-'));
const servers = [];
let browser = null;
try {
  const good = path.join(tmp, 'good');
  execFileSync(arwb, ['export', '--scene', scene, '--out', good, '--web', '--quiet'], { stdio: 'pipe' });
  // Each changed copy on a server of its own: another origin, so no service worker of another copy answers.
  const sceneBytes = fs.statSync(path.join(good, 'scene/museum.lua')).size, edit = '-- edited after export\n';
  const changes = [
    ['scene/museum.lua', (f) => fs.appendFileSync(f, edit),
     `scene/museum.lua: changed since export (${sceneBytes + edit.length} bytes, the manifest says ${sceneBytes})`],
    ['web/arwb_core.wasm', (f) => { const b = fs.readFileSync(f); b[b.length - 1] ^= 1; fs.writeFileSync(f, b); },
     'web/arwb_core.wasm: changed since export (SHA-256 differs)'],
    ['markers.pdf', (f) => fs.rmSync(f), 'markers.pdf: missing (listed in the manifest'],
  ];
  browser = await Chromium.launch();
  const open = async (folder) => {
    const server = await serve([folder]);
    servers.push(server);
    const page = await browser.newPage(server.url);
    await page.waitFor('window.arwbPlayer && arwbPlayer.state !== "checking"', 60);
    return page;
  };
  for (const [file, change, said] of changes) {
    const copy = path.join(tmp, file.replace(/[/.]/g, '_'));
    fs.cpSync(good, copy, { recursive: true });
    change(path.join(copy, file));
    const page = await open(copy);
    const [state, problem, text, disabled] = await page.evaluate(
      '[arwbPlayer.state, arwbPlayer.bundle.problem, document.getElementById("bundle").innerText, ' +
      'document.getElementById("start").disabled]');
    if (state !== 'refused' || !problem.startsWith(said) || !text.includes(said) || disabled !== true)
      fail(`with ${file} changed the page said ${JSON.stringify({ state, problem, text, disabled })}`);
    else console.log(`${file} changed: refused, "${problem}"`);
  }
  const page = await open(good);
  const state = await page.evaluate('[arwbPlayer.state, arwbPlayer.bundle.state, arwbPlayer.bundle.offline]');
  if (state.join() !== 'ready,verified,true') fail(`the untouched bundle's page is ${state.join(', ')}`);
  if (page.exceptions.length) fail(`the page threw: ${page.exceptions.join('; ')}`);
} catch (e) {
  fail(e.message);
} finally {
  if (browser) await browser.close();
  for (const s of servers) s.close();
  fs.rmSync(tmp, { recursive: true, force: true });
}
if (failures.length) {
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(1);
}
