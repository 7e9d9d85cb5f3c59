// The phone player's worker: the WebAssembly core (arwb_core.js, the desktop's detector) on frames the page sends.
// Messages in: {type: 'detect', width, height, rgba: Uint8ClampedArray}, {type: 'dictionaries', list} and
// {type: 'camera', files: [{path, bytes}], path, side} (the bundle's calibration files, written into the core's file
// system under /bundle/, the one to read, '' for the default camera, and the markers' side).
// Out: {type: 'ready'}, {type: 'camera', camera} (what the poses use, in words), {type: 'result', result, width, height, rgba} (the pixels go back to the page, which keeps
// the frame it drew and what was found in it), {type: 'error', message}.
'use strict';
importScripts('arwb_core.js');

let core = null;
const ready = ArwbCore().then((m) => {
  core = {
    module: m,
    frame: m.cwrap('arwb_frame', 'number', ['number', 'number']),
    detect: m.cwrap('arwb_detect', 'string', []),
    dictionaries: m.cwrap('arwb_set_dictionaries', 'string', ['string']),
    camera: m.cwrap('arwb_set_camera', 'string', ['string', 'number']),
  };
  postMessage({ type: 'ready' });
}, (e) => postMessage({ type: 'error', message: `the detector did not load: ${e && e.message ? e.message : e}` }));

onmessage = async (e) => {
  await ready;
  if (!core) return;
  const msg = e.data;
  if (msg.type === 'dictionaries') {
    const error = core.dictionaries(msg.list);
    if (error) postMessage({ type: 'error', message: error });
    return;
  }
  if (msg.type === 'camera') {
    let error = '';
    if (msg.path) {
      try {
        for (const f of msg.files) {
          const file = `/bundle/${f.path}`;
          core.module.FS.mkdirTree(file.slice(0, file.lastIndexOf('/')));
          core.module.FS.writeFile(file, f.bytes);
        }
        error = core.camera(`/bundle/${msg.path}`, msg.side);
      } catch (e) {
        error = `the calibration could not be written for the detector: ${e.message}`;
      }
      if (!error) return postMessage({ type: 'camera', camera: `calibrated (${msg.path})` });
      postMessage({ type: 'error', message: `the calibration is not used: ${error}` });
    }
    // The default camera, also when the bundle's calibration was refused: poses, marked assumed.
    const fallback = core.camera('', msg.side);
    if (fallback) postMessage({ type: 'error', message: `no poses: ${fallback}` });
    postMessage({ type: 'camera', camera: fallback ? 'none' : msg.path ? 'assumed (the calibration was refused)'
                                                                     : 'assumed (the bundle has no calibration)' });
    return;
  }
  if (msg.type !== 'detect') return;
  const at = core.frame(msg.width, msg.height);
  if (!at) {
    postMessage({ type: 'error', message: `a camera frame of ${msg.width}x${msg.height} is too large to search` });
    postMessage({ type: 'result', result: { markers: [], ms: 0 }, width: msg.width, height: msg.height,
                  rgba: msg.rgba }, [msg.rgba.buffer]);
    return;
  }
  core.module.HEAPU8.set(msg.rgba, at);
  const result = JSON.parse(core.detect());
  postMessage({ type: 'result', result, width: msg.width, height: msg.height, rgba: msg.rgba }, [msg.rgba.buffer]);
};
