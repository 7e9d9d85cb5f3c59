// The phone player's worker: the WebAssembly core (arwb_core.js, the desktop's detector) on frames the page sends.
// Messages in: {type: 'detect', width, height, rgba: Uint8ClampedArray, t}, {type: 'dictionaries', list},
// {type: 'param', name, value} (one row of the detector's parameter table), {type: 'mesh', id} (a mesh a scene step
// named) and
// {type: 'camera', files: [{path, bytes}], path, side} (the bundle's calibration files, written into the core's file
// system under /bundle/, the one to read, '' for the default camera, and the markers' side) and {type: 'scene',
// scene, files: [{path, blob}], videos: [{path, width, height, duration}]} (the scene file's bundle path, the
// files of its folder, mounted read-only under /files/ where the core reads only the bytes it asks for, and each
// video's size and length as the page's <video> read them).
// Out: {type: 'ready'}, {type: 'camera', camera} (what the poses use, in words), {type: 'scene', status, selfTest}
// (the scene's load status, and the bundle's self-test run by this core: WebScene::self_test's rows),
// {type: 'mesh', id, parts: [{vertices: Float32Array, indices: Uint32Array, colour, lit, normals, uvs,
// overlay_texture, texture, picture}], pictures: [Uint8Array], source} (asked for, or sent ahead of the first frame
// that draws it) or {type: 'mesh', id, error}
// (WebScene::mesh's, the arrays and a model's texture files copied out of the core's memory), {type: 'result',
// result, scene, width, height, rgba} (the pixels go back to the page, which keeps the frame it drew and what was
// found in it; scene: the core's overlays for it, when a scene runs), {type: 'error', message}.
'use strict';
importScripts('arwb_core.js');

let core = null;
let sceneRunning = false;
const meshesSent = new Set();   // ids of the meshes sent unasked (the page asks again for one it has let go)

// A mesh a scene step named, to the page: WebScene::mesh's, its arrays and a model's pictures copied out of the
// core's memory.
function sendMesh(id) {
  meshesSent.add(id);
  const mesh = JSON.parse(core.sceneMesh(id));
  if (mesh.error) return postMessage({ type: 'mesh', id, error: mesh.error });
  const buffer = core.module.HEAPU8.buffer;   // after the call: memory may have grown
  const parts = mesh.parts.map((p) => Object.assign(p, {
    vertices: new Float32Array(buffer, p.vertices, p.floats).slice(),
    indices: new Uint32Array(buffer, p.indices, p.count).slice(),
  }));
  const pictures = mesh.pictures.map((p) => new Uint8Array(buffer, p.bytes, p.length).slice());
  return postMessage({ type: 'mesh', id, source: mesh.source, parts, pictures },
                     parts.flatMap((p) => [p.vertices.buffer, p.indices.buffer]).concat(pictures.map((p) => p.buffer)));
}

// The scene's folder mounted read-only (WORKERFS: the core reads the Blobs' bytes as it asks), and the scene loaded.
function loadScene(msg) {
  const FS = core.module.FS;
  try { FS.unmount('/files'); } catch { /* not mounted yet */ }
  FS.mkdirTree('/files');
  // WORKERFS answers readlink with EPERM; without its own readlink the file system says EINVAL, "not a link", which
  // is what realpath (the scene's std::filesystem::canonical) asks each part of a path.
  delete FS.filesystems.WORKERFS.node_ops.readlink;
  FS.mount(FS.filesystems.WORKERFS, { blobs: msg.files.map((f) => ({ name: f.path, data: f.blob })) }, '/files');
  for (const v of msg.videos) core.sceneVideo(`/files/${v.path}`, v.width, v.height, v.duration);
  const status = JSON.parse(core.sceneLoad(`/files/${msg.scene}`));
  sceneRunning = true;
  // The bundle's self-test again, on this core, beside the scene just loaded.
  const selfTest = status.ok ? JSON.parse(core.sceneSelfTest(`/files/${msg.scene}`)) : null;
  return { status, selfTest };
}
const ready = ArwbCore().then((m) => {
  core = {
    module: m,
    frame: m.cwrap('arwb_frame', 'number', ['number', 'number']),
    detect: m.cwrap('arwb_detect', 'string', []),
    dictionaries: m.cwrap('arwb_set_dictionaries', 'string', ['string']),
    param: m.cwrap('arwb_set_param', 'string', ['string', 'number']),
    camera: m.cwrap('arwb_set_camera', 'string', ['string', 'number']),
    sceneLoad: m.cwrap('arwb_scene_load', 'string', ['string']),
    sceneVideo: m.cwrap('arwb_scene_video', null, ['string', 'number', 'number', 'number']),
    sceneStep: m.cwrap('arwb_scene_step', 'string', ['number']),
    sceneMesh: m.cwrap('arwb_scene_mesh', 'string', ['number']),
    sceneSelfTest: m.cwrap('arwb_scene_self_test', 'string', ['string']),
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
  if (msg.type === 'param') {
    const error = core.param(msg.name, msg.value);
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
  if (msg.type === 'scene') {
    let loaded;
    try {
      loaded = loadScene(msg);
    } catch (e) {
      loaded = { status: { ok: false, error: `the scene's files could not be given to the core: ${e.message}` } };
    }
    postMessage(Object.assign({ type: 'scene' }, loaded));
    return;
  }
  if (msg.type === 'mesh') return sendMesh(msg.id);
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
  const scene = sceneRunning ? JSON.parse(core.sceneStep(msg.t)) : null;
  // A mesh the scene names for the first time goes ahead of the frame that draws it.
  for (const o of scene ? scene.overlays : [])
    if (o.solid && o.solid.mesh && !meshesSent.has(o.solid.mesh)) sendMesh(o.solid.mesh);
  postMessage({ type: 'result', result, scene, width: msg.width, height: msg.height, rgba: msg.rgba },
              [msg.rgba.buffer]);
};
