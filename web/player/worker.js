// The phone player's worker: the WebAssembly core (arwb_core.js, the desktop's detector) on frames the page sends.
// Messages in: {type: 'detect', width, height, rgba: Uint8ClampedArray} and {type: 'dictionaries', list}.
// Out: {type: 'ready'}, {type: 'result', result, width, height, rgba} (the pixels go back to the page, which keeps
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
