// The WebAssembly core finds what `arwb detect` finds: the same ids, dictionaries and order on the same synthetic
// photographs, corners within 1e-3 px (detect --json prints them to 3 decimals). Run by ctest as
//   node --no-experimental-fetch detect_matches_native.mjs ARWB CORE_JS
// Prints the frames, the markers, the largest corner difference and both detectors' median milliseconds.
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { compareWithNative, loadCore, readPng, tallyProblems } from './web_support.mjs';

const [arwb, coreJs] = process.argv.slice(2);
const failures = [];
const fail = (message) => failures.push(message);
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-web-'));
try {
  const frames = path.join(tmp, 'frames');
  execFileSync(arwb, ['synth', '--out', frames, '--count', '12', '--seed', '11', '--size', 'mixed'], { stdio: 'pipe' });
  const native = execFileSync(arwb, ['detect', '--json', frames],
                              { encoding: 'utf8', maxBuffer: 1 << 26, stdio: ['ignore', 'pipe', 'pipe'] })
    .trim().split('\n').map((line) => JSON.parse(line));
  const core = await loadCore(coreJs);

  // A wrong dictionary is refused with its name, and the one in use stays.
  const refusal = core.setDictionaries('NO_SUCH_DICT');
  if (!refusal.includes('NO_SUCH_DICT')) fail(`an unknown dictionary was not refused by name: "${refusal}"`);

  const tally = { markers: 0, worst: 0 };
  const msWasm = [], msNative = [];
  for (const want of native) {
    const name = path.basename(want.source);
    const got = core.detect(readPng(want.source));
    if (got.error) { fail(`${name}: ${got.error}`); continue; }
    msWasm.push(got.ms);
    msNative.push(want.ms);
    const problem = compareWithNative(name, got, want, tally);
    if (problem) fail(problem);
  }
  if (native.length !== 12) fail(`arwb detect gave ${native.length} frames of 12`);
  tallyProblems(tally).forEach(fail);
  console.log(`${native.length} frames, ${tally.markers} markers, the same ids; corners differ by up to ` +
              `${tally.worst.toFixed(6)} px; median ms: WebAssembly ${median(msWasm).toFixed(2)} (Node), ` +
              `native ${median(msNative).toFixed(2)}`);
} finally {
  fs.rmSync(tmp, { recursive: true, force: true });
}
if (failures.length) {
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(1);
}
