// The WebAssembly core's marker poses are `arwb detect --marker-size`'s: on the same synthetic photographs, with
// the default camera and with a calibration with lens distortion (written into the core's file system as the page
// writes the bundle's), both solutions of each marker's pose agree with the native ones to the 6 decimals
// `arwb detect --json` prints, with the same errors and ambiguity to its 4. A calibration made for another shape
// of picture is refused with the desktop's words. Run by ctest as
//   node --no-experimental-fetch pose_matches_native.mjs ARWB CORE_JS
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { loadCore, readPng } from './web_support.mjs';

const [arwb, coreJs] = process.argv.slice(2);
const failures = [];
const fail = (message) => failures.push(message);
const run = (args) => execFileSync(arwb, args, { encoding: 'utf8', maxBuffer: 1 << 26, stdio: ['ignore', 'pipe', 'pipe'] });

// A matrix of an OpenCV YAML file (`name: !!opencv-matrix ... data: [...]`) as its numbers.
function yamlMatrix(text, name) {
  const m = text.match(new RegExp(`${name}: !!opencv-matrix[^\\[]*\\[([^\\]]*)\\]`));
  if (!m) throw new Error(`no ${name} in the calibration`);
  return m[1].split(',').map(Number);
}

// A marker-frame point projected with OpenCV's lens model (k1 k2 p1 p2 [k3 [k4 k5 k6]]), written here from its
// documented formula: the core's axes are checked against arithmetic that shares no code with OpenCV's.
function project([X, Y, Z], rvec, tvec, K, dist) {
  const th = Math.hypot(...rvec);
  const [kx, ky, kz] = th > 0 ? rvec.map((v) => v / th) : [0, 0, 0];
  const c = Math.cos(th), s = Math.sin(th), v = 1 - c;
  const R = [[c + kx * kx * v, kx * ky * v - kz * s, kx * kz * v + ky * s],
             [ky * kx * v + kz * s, c + ky * ky * v, ky * kz * v - kx * s],
             [kz * kx * v - ky * s, kz * ky * v + kx * s, c + kz * kz * v]];
  const P = R.map((row, i) => row[0] * X + row[1] * Y + row[2] * Z + tvec[i]);
  const x = P[0] / P[2], y = P[1] / P[2], r2 = x * x + y * y;
  const [k1, k2, p1, p2, k3, k4, k5, k6] = [...dist, 0, 0, 0, 0, 0, 0, 0, 0];
  const radial = (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)));
  const xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return [K[0] * xd + K[1] * yd + K[2], K[4] * yd + K[5]];
}

// The largest difference between two vectors, relative to 1 or to the value's own size, whichever is larger.
function differs(a, b) {
  return Math.max(...a.map((x, i) => Math.abs(x - b[i]) / Math.max(1, Math.abs(b[i]))));
}

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-pose-'));
try {
  const frames = path.join(tmp, 'frames');
  run(['synth', '--out', frames, '--count', '10', '--seed', '7', '--size', '640x480']);
  run(['synth', '--chessboard', '--out', path.join(tmp, 'views'), '--count', '1']);
  const calib = path.join(tmp, 'views', 'truth_camera.yml');
  const core = await loadCore(coreJs);
  core.writeFile('/bundle/calibration/camera.yml', fs.readFileSync(calib));

  const text = fs.readFileSync(calib, 'utf8');
  const f = 320 / Math.tan(Math.PI / 6);   // pose/marker_pose.hpp's default camera at 640x480
  const cameras = { 'default camera': [[f, 0, 319.5, 0, f, 239.5, 0, 0, 1], []],
                    calibrated: [yamlMatrix(text, 'camera_matrix'), yamlMatrix(text, 'distortion_coefficients')] };
  const tally = { poses: 0, worst: 0, worstError: 0, worstAxis: 0 };
  for (const [label, calibArgs, corePath] of [['default camera', [], ''],
                                              ['calibrated', ['--calib', calib], '/bundle/calibration/camera.yml']]) {
    const said = core.setCamera(corePath, 50);
    if (said) { fail(`${label}: setCamera said ${said}`); continue; }
    const native = run(['detect', '--json', '--marker-size', '50', ...calibArgs, frames]).trim().split('\n')
      .map((line) => JSON.parse(line));
    for (const want of native) {
      const name = `${label}, ${path.basename(want.source)}`;
      const got = core.detect(readPng(want.source));
      if (got.error || got.camera_error) { fail(`${name}: ${got.error || got.camera_error}`); continue; }
      if (got.markers.length !== want.markers.length) { fail(`${name}: ${got.markers.length} markers, native ${want.markers.length}`); continue; }
      want.markers.forEach((w, i) => {
        const g = got.markers[i];
        if (!w.pose || !g.pose) { if (!w.pose !== !g.pose) fail(`${name}: id ${w.id}: a pose on one side only`); return; }
        const d = Math.max(differs(g.pose.rvec, w.pose.rvec), differs(g.pose.tvec, w.pose.tvec),
                           differs(g.pose.alternative.rvec, w.pose.alternative.rvec),
                           differs(g.pose.alternative.tvec, w.pose.alternative.tvec));
        const e = Math.max(Math.abs(g.pose.error_px - w.pose.error_px), Math.abs(g.pose.ambiguity - w.pose.ambiguity));
        tally.worst = Math.max(tally.worst, d);
        tally.worstError = Math.max(tally.worstError, e);
        tally.poses++;
        if (d > 2e-6) fail(`${name}: id ${w.id}: pose differs by ${d.toExponential(2)} (relative; allowed 2e-6)`);
        if (e > 1.5e-4) fail(`${name}: id ${w.id}: error or ambiguity differs by ${e.toExponential(2)}`);
        if (g.pose.camera !== w.pose.camera) fail(`${name}: id ${w.id}: camera ${g.pose.camera}, native ${w.pose.camera}`);
        // The axes the page draws: the origin and each axis's end, one side (50) long, through the lens.
        const [K, dist] = cameras[label];
        [[0, 0, 0], [50, 0, 0], [0, 50, 0], [0, 0, 50]].forEach((point, k) => {
          const [u, v] = project(point, g.pose.rvec, g.pose.tvec, K, dist);
          const a = Math.hypot(u - g.pose.axes[k][0], v - g.pose.axes[k][1]);
          tally.worstAxis = Math.max(tally.worstAxis, a);
          if (!(a < 1e-6)) fail(`${name}: id ${w.id}: axis point ${k} at ${g.pose.axes[k]}, projected ${[u, v]}`);
        });
      });
    }
  }
  if (tally.poses < 10) fail(`only ${tally.poses} poses compared`);

  // A calibration made for 640x480 does not fit a 640x360 frame: said, with no poses, as the desktop says it.
  core.setCamera('/bundle/calibration/camera.yml', 50);
  const wide = { width: 640, height: 360, data: new Uint8Array(640 * 360 * 4).fill(255) };
  const refused = core.detect(wide);
  if (!refused.camera_error || !refused.camera_error.includes('made for 640x480'))
    fail(`a 640x360 frame with a 640x480 calibration said ${JSON.stringify(refused.camera_error)}`);
  const missing = core.setCamera('/bundle/none.yml', 50);
  if (!missing.includes('/bundle/none.yml')) fail(`a missing calibration said "${missing}"`);
  console.log(`${tally.poses} poses compared (default camera and calibrated); they differ from arwb detect's by up ` +
              `to ${tally.worst.toExponential(2)} (relative), errors and ambiguity by ${tally.worstError.toExponential(2)}; ` +
              `the axes lie within ${tally.worstAxis.toExponential(2)} px of the lens model's projection`);
} catch (e) {
  fail(e.stack || e.message);
} finally {
  fs.rmSync(tmp, { recursive: true, force: true });
}
if (failures.length) {
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(1);
}
