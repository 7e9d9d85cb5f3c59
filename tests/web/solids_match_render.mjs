// The scene's solids on the phone, against `arwb render` (render_support.mjs): a bundle with a calibration (so that
// flat media are drawn through the lens model too) and a scene of a cube with a picture on its top face on marker
// 0, the axes and a text card on marker 1 and a picture on marker 2. Run by ctest as
//   node --no-experimental-fetch solids_match_render.mjs ARWB CORE_JS
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { comparisonTest, judge, pageAgainstRender } from './render_support.mjs';

const [arwb] = process.argv.slice(2);
const museum = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../scripts/museum');

await comparisonTest('arwb-solids-', async (tmp, fail) => {
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
  execFileSync(arwb, ['synth', '--chessboard', '--out', path.join(tmp, 'views'), '--count', '1'], { stdio: 'pipe' });
  const calib = path.join(tmp, 'views', 'truth_camera.yml');
  judge(await pageAgainstRender({ arwb, tmp, scene, calib, kinds: ['cube', 'axes', 'image', 'text'] }), 2000, fail);
});
