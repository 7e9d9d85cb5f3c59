// The phone player's page: checks what it needs and says how to fix what is missing, checks the bundle it is part
// of (its files against manifest.json, through the service worker sw.js, which keeps them for offline use), starts
// the camera on one tap, hands frames to the worker (worker.js: the WebAssembly core) and draws each camera frame
// with what the worker last found. Drawing never waits for detection: a frame goes to the worker only when it is
// idle.
// window.arwbPlayer is the page's state for the overlay and the tests (tests/web).
'use strict';
(() => {
  const $ = (id) => document.getElementById(id);
  // A module of one function returning a v128 (i32.const 0; i8x16.splat): valid only where WebAssembly has SIMD,
  // which the core is built with.
  const simdModule = new Uint8Array([0, 97, 115, 109, 1, 0, 0, 0, 1, 5, 1, 96, 0, 1, 123, 3, 2, 1, 0, 10, 8, 1, 6, 0,
                                     65, 0, 253, 15, 11]);
  const hasWebGL = () => {
    try { return !!document.createElement('canvas').getContext('webgl2'); } catch { return false; }
  };
  // [what, passes, the fix in plain words (or a function giving it), needed to start]
  const checks = [
    ['a secure page', () => window.isSecureContext,
     'Open this page over HTTPS (or, on the computer that serves it, at http://127.0.0.1).', true],
    ['the camera', () => !!(navigator.mediaDevices && navigator.mediaDevices.getUserMedia),
     () => (window.isSecureContext ? 'Open this page in Safari or Chrome itself, not inside another app.'
                                   : 'Browsers give the camera only to a secure page (above).'), true],
    ['WebAssembly with SIMD', () => typeof WebAssembly === 'object' && WebAssembly.validate(simdModule),
     'This browser is too old to run the detector: update it (Safari 16.4, Chrome 91, Firefox 89 or later).', true],
    ['background workers', () => typeof Worker === 'function', 'This browser cannot run workers: update it.', true],
    ['3D graphics (WebGL 2)', hasWebGL, '3D media will not be shown: turn on WebGL or hardware acceleration.', false],
  ];

  const player = window.arwbPlayer = {
    state: 'checking',   // checking, blocked, refused (the bundle), ready, starting, running, failed
    facing: 'environment',
    drawn: 0,            // camera frames drawn
    detected: 0,         // frames the worker searched
    fps: 0,
    detectMs: [],        // the worker's last 30 times
    markers: [],
    camera: 'none yet',  // what the poses are computed with
    cameraError: '',     // why the calibration does not fit the camera's picture, '' when it does
    errors: [],          // newest last
    notes: [],           // what the page does not do for this bundle (media it does not draw yet), once each
    lastFrame: null,     // {width, height, rgba, result}: a frame the worker searched and what it found
    selfTest: null,      // {passed, text, rows}: the bundle's self-test run by this device's core (checkSelfTest)
    // The scene: its load status from the core, the overlays of the last searched frame (the core's JSON), the kinds
    // of media drawn over the view on the last frame; line: the overlay's line about it.
    scene: { status: null, overlays: [], drawn: [], console: [], line: () => sceneLine() },
    // The bundle this page belongs to: state checking, none (the page alone), unchecked (the page cannot run here),
    // verified or refused; its manifest;
    // problem (the first file refused, named); offline (the service worker keeps it).
    bundle: { state: 'checking', manifest: null, problem: '', offline: false },
    // One row of the detector's parameter table, as presets and sliders set it (for the tests and the console:
    // full_search_interval 1 searches every frame whole, as `arwb detect` searches still images).
    setParam(name, value) { worker.postMessage({ type: 'param', name, value }); },
    // The last searched frame as a PNG data URL, with its result (for the tests: `arwb detect` on the same pixels).
    grab() {
      const f = player.lastFrame;
      if (!f) return null;
      const c = document.createElement('canvas');
      c.width = f.width;
      c.height = f.height;
      c.getContext('2d').putImageData(new ImageData(new Uint8ClampedArray(f.rgba), f.width, f.height), 0, 0);
      return { png: c.toDataURL('image/png'), result: f.result };
    },
    // The last searched frame with its scene's media drawn over it, as the view shows them, and the frame alone, as
    // PNG data URLs, with what was found (for the tests: `arwb render` on the same pixels). Null before a search.
    composite() {
      const f = player.lastFrame;
      const m = player.bundle.manifest;
      if (!f || !m || !m.scene) return null;
      const frame = player.grab();
      layer.draw(f.overlays, f.width, f.height, sceneDir(m));
      const c = document.createElement('canvas');
      c.width = f.width;
      c.height = f.height;
      const g = c.getContext('2d');
      g.putImageData(new ImageData(new Uint8ClampedArray(f.rgba), f.width, f.height), 0, 0);
      g.drawImage($('media'), 0, 0);   // read in the task that drew it, before the page shows it
      return { png: c.toDataURL('image/png'), frame: frame.png, result: f.result, drawn: layer.drawn };
    },
  };
  const report = (message) => {
    player.errors.push(message);
    if (player.errors.length > 20) player.errors.shift();
  };

  function runChecks() {
    let blocked = false;
    const list = $('checks');
    const advice = [];
    for (const [what, passes, fixText, needed] of checks) {
      const fix = typeof fixText === 'function' ? fixText() : fixText;
      let ok = false;
      try { ok = passes(); } catch { ok = false; }
      const li = document.createElement('li');
      li.className = ok ? 'ok' : 'bad';
      li.textContent = ok ? what : `${what}: ${fix}`;
      list.appendChild(li);
      if (!ok && needed) blocked = true;
      if (!ok) advice.push(fix);
    }
    if (blocked) $('advice').textContent = advice[0];
    return !blocked;
  }

  // Waits for a service worker registration's new worker to be activated (true) or given up (false).
  const settled = (registration) => new Promise((resolve) => {
    const sw = registration.installing || registration.waiting || registration.active;
    if (!sw) return resolve(false);
    const check = () => {
      if (sw.state === 'activated') resolve(true);
      else if (sw.state === 'redundant') resolve(false);
    };
    sw.addEventListener('statechange', check);
    check();
  });

  // The bundle's files checked: by the service worker as it keeps them (sw.js), or here when it cannot (no service
  // worker in this browser, or its install failed: then this names the file).
  async function checkBundle() {
    const b = player.bundle;
    let m;
    try {
      m = await arwbVerify.manifest(location.href);
    } catch (e) {
      b.state = 'refused';
      b.problem = e.message;
      return;
    }
    if (!m) {
      b.state = 'none';
      return;
    }
    b.manifest = m.parsed;
    $('title').textContent = m.parsed.title || 'ArUco Workbench player';
    $('bundle').textContent = `Checking the bundle's ${m.parsed.files.length} files...`;
    if ('serviceWorker' in navigator) {
      try {
        const registration = await navigator.serviceWorker.register(`sw.js?manifest=${m.digest}`);
        b.offline = await settled(registration);
      } catch (e) {
        report(`the bundle is not kept for offline use: ${e.message}`);
      }
    }
    if (!b.offline) {
      const checked = await arwbVerify.files(location.href, m.parsed.files);
      if (checked.problems.length) {
        b.state = 'refused';
        b.problem = checked.problems[0];
        return;
      }
    }
    b.state = 'verified';
  }

  const worker = new Worker('web/worker.js');
  let workerReady = false, workerBusy = false;
  // The bundle's dictionary, and its camera for the markers' poses: its calibration's files (the paper's pair is two)
  // handed to the worker, else the default camera; the markers' side in mm, as printed on its sheet. Once, when both
  // the worker and the bundle's check are done (whichever ends last calls it), so that the scene is loaded and its
  // self-test run once, on files already checked.
  let bundleUsed = null;
  const useBundle = async () => {
    const m = player.bundle.manifest;
    const state = player.bundle.state;
    if (!workerReady || !m || state === 'checking' || state === 'refused' || bundleUsed === m) return;
    bundleUsed = m;
    worker.postMessage({ type: 'dictionaries', list: m.dictionary });
    let files = [];
    try {
      for (const f of m.files.filter((file) => file.role === 'calibration')) {
        const r = await fetch(f.path);
        if (!r.ok) throw new Error(`${f.path}: HTTP ${r.status}`);
        files.push({ path: f.path, bytes: new Uint8Array(await r.arrayBuffer()) });
      }
    } catch (e) {
      report(`the calibration could not be read (${e.message}): poses use the default camera`);
      files = [];
    }
    // The worker says which camera it took (the 'camera' reply).
    worker.postMessage({ type: 'camera', files, path: files.length ? m.calibration : '', side: m.marker_size_mm });
    if (m.scene) {
      try {
        worker.postMessage(Object.assign({ type: 'scene' }, await sceneFiles(m)));
      } catch (e) {
        report(`the scene does not run: ${e.message}`);
      }
    }
  };
  // The bundle file a phone plays for `path`: its phone copy when export made one (--convert-for-phones).
  const phonePath = (m, path) => ((m.phone_media || []).find((c) => c.path === path) || { phone: path }).phone;
  // The scene's files as Blobs, fetched once for the core (sceneFiles) and drawn from the same Blobs, by bundle path.
  const sceneBlobs = new Map();
  const bundleFile = async (path) => {
    if (sceneBlobs.has(path)) return sceneBlobs.get(path);
    const r = await fetch(path);
    if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
    return r.blob();
  };
  const sceneDir = (m) => m.scene.slice(0, m.scene.lastIndexOf('/'));
  // The scene's folder for the core: its files as Blobs (each video as the phone plays it, under the original's name,
  // which the scene wrote), and each video's size and length as this browser reads them.
  async function sceneFiles(m) {
    const dir = sceneDir(m);
    const files = [], videos = [];
    for (const f of m.files.filter((file) => file.path.startsWith(`${dir}/`))) {
      const blob = await bundleFile(phonePath(m, f.path));
      sceneBlobs.set(phonePath(m, f.path), blob);
      files.push({ path: f.path, blob });
      if (!/\.(mp4|m4v|mov|webm|mkv|avi|ogv)$/i.test(f.path)) continue;
      const v = document.createElement('video');
      v.muted = true;
      v.preload = 'metadata';
      v.src = URL.createObjectURL(blob);
      const ok = await new Promise((resolve) => {
        v.onloadedmetadata = () => resolve(true);
        v.onerror = () => resolve(false);
        setTimeout(() => resolve(false), 5000);
      });
      URL.revokeObjectURL(v.src);
      if (ok && v.videoWidth > 0)
        videos.push({ path: f.path, width: v.videoWidth, height: v.videoHeight, duration: v.duration });
      else report(`${f.path}: this browser cannot play it (export with --convert-for-phones makes a copy it plays)`);
    }
    return { scene: m.scene, files, videos };
  }
  const layer = new MediaLayer($('media'), (path) => bundleFile(phonePath(player.bundle.manifest, path)),
                                (url, title) => {
                                  const c = (player.bundle.manifest.web_cards || [])
                                    .find((w) => w.url === url && w.title === title);
                                  return c ? c.picture : '';
                                },
                                (id) => worker.postMessage({ type: 'mesh', id }), (message) => report(message));
  const notDrawn = new Set();   // the kinds said not to be drawn on phones yet, once per scene
  worker.onmessage = (e) => {
    const msg = e.data;
    if (msg.type === 'ready') {
      workerReady = true;
      useBundle();
    }
    else if (msg.type === 'error') report(msg.message);
    else if (msg.type === 'camera') player.camera = msg.camera;
    else if (msg.type === 'mesh') layer.mesh(msg);
    else if (msg.type === 'scene') {
      player.scene.status = msg.status;
      notDrawn.clear();
      player.notes = [];
      if (!msg.status.ok) report(`the scene did not load: ${msg.status.error}`);
      player.selfTest = checkSelfTest(msg.selfTest, player.bundle.manifest);
      if (player.selfTest) {
        $('selftest').textContent = `Self-test on this device: ${player.selfTest.text}.`;
        $('selftest').className = player.selfTest.passed ? 'bundle' : 'advice';
        if (!player.selfTest.passed) report(`self-test: ${player.selfTest.text}`);
      }
    }
    else if (msg.type === 'result') {
      workerBusy = false;
      player.detected++;
      player.markers = msg.result.markers || [];
      // A calibration that does not fit the camera's picture: said once per size, and the markers have no pose.
      if (msg.result.camera_error && msg.result.camera_error !== player.cameraError) {
        player.cameraError = msg.result.camera_error;
        report(`no poses: ${msg.result.camera_error}`);
      }
      player.detectMs.push(msg.result.ms || 0);
      if (player.detectMs.length > 30) player.detectMs.shift();
      player.lastFrame = { width: msg.width, height: msg.height, rgba: msg.rgba, result: msg.result,
                           overlays: msg.scene ? msg.scene.overlays : [] };
      if (msg.scene) takeScene(msg.scene);
      drawOverlay();
    }
  };
  worker.onerror = (e) => report(`the detector stopped: ${e.message}`);

  // The bundle's self-test as this device's core ran it (the worker's), against the one export ran (the manifest's
  // rows): it passes when every mapping fires here for every id, as each did at export.
  function checkSelfTest(t, m) {
    if (!t) return null;
    if (t.error) return { passed: false, text: `it could not run: ${t.error}`, rows: [] };
    const exported = (m && m.self_test) || [];
    const here = (r) => t.rows.find((p) => p.id === r.id && p.line === r.line);
    const failed = t.rows.find((p) => !p.fired) || exported.find((r) => !here(r));
    const fired = t.rows.filter((p) => p.fired).length;
    const rows = t.rows;
    if (!failed) return { passed: true, rows, text: `${fired} of ${rows.length} mappings fire, as at export` };
    const why = failed.detail || 'not tested here';
    return { passed: false, rows, text: `marker ${failed.id} (line ${failed.line}) does not fire here: ${why}` };
  }

  // One frame's scene from the core: its overlays to draw, its new error lines, its console.
  function takeScene(scene) {
    player.scene.overlays = scene.overlays;
    for (const e of scene.errors) report(e);
    if (scene.scene.console) player.scene.console = scene.scene.console;
    for (const o of scene.overlays) {
      // Every kind but the detector's stage pictures, which need the trace the page's core does not keep.
      if (o.kind !== 'stage' || notDrawn.has(o.kind)) continue;
      notDrawn.add(o.kind);
      player.notes.push(`stage pictures are not drawn on phones (marker ${o.marker}: ${o.source}); the desktop ` +
                        'draws them');
    }
  }

  const video = $('camera');
  const view = $('view');
  const ctx = view.getContext('2d', { willReadFrequently: true });
  let stream = null;

  async function openCamera() {
    if (stream) stream.getTracks().forEach((t) => t.stop());
    stream = await navigator.mediaDevices.getUserMedia({
      audio: false,
      video: { facingMode: player.facing, width: { ideal: 1280 }, height: { ideal: 720 } },
    });
    video.srcObject = stream;
    await video.play();
  }

  async function start() {
    player.state = 'starting';
    $('start').disabled = true;
    try {
      await openCamera();
    } catch (e) {
      player.state = 'failed';
      $('start').disabled = false;
      $('advice').textContent = e && e.name === 'NotAllowedError'
        ? 'Allow the camera for this page (the camera icon in the address bar, or the browser\'s site settings), ' +
          'then tap Start again.'
        : `The camera did not start (${e && e.name ? e.name : e}): close other apps that use it and tap Start again.`;
      return;
    }
    $('first').hidden = true;
    $('stage').hidden = false;
    player.state = 'running';
    requestAnimationFrame(frame);
  }

  let fpsCount = 0, fpsSince = performance.now();
  function frame(now) {
    requestAnimationFrame(frame);
    if (video.readyState < 2 || !video.videoWidth) return;
    const w = video.videoWidth, h = video.videoHeight;
    if (view.width !== w || view.height !== h) { view.width = w; view.height = h; }
    ctx.drawImage(video, 0, 0, w, h);
    if (workerReady && !workerBusy) {
      const rgba = ctx.getImageData(0, 0, w, h).data;
      workerBusy = true;
      worker.postMessage({ type: 'detect', width: w, height: h, rgba, t: now / 1000 }, [rgba.buffer]);
    }
    drawMarkers();
    const m = player.bundle.manifest;
    if (m && m.scene) {
      layer.draw(player.scene.overlays, w, h, sceneDir(m));
      player.scene.drawn = layer.drawn;
    }
    player.drawn++;
    fpsCount++;
    if (now - fpsSince >= 1000) {
      player.fps = (fpsCount * 1000) / (now - fpsSince);
      fpsCount = 0;
      fpsSince = now;
      drawOverlay();
    }
  }

  function drawMarkers() {
    ctx.lineWidth = Math.max(2, view.width / 320);
    ctx.font = `${Math.round(view.width / 30)}px system-ui, sans-serif`;
    for (const m of player.markers) {
      ctx.strokeStyle = '#3f3';
      ctx.beginPath();
      m.corners.forEach(([x, y], i) => (i ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
      ctx.closePath();
      ctx.stroke();
      ctx.fillStyle = '#f33';
      ctx.fillRect(m.corners[0][0] - 3, m.corners[0][1] - 3, 6, 6);
      ctx.fillStyle = '#3f3';
      ctx.fillText(String(m.id), m.corners[0][0] + 6, m.corners[0][1] - 6);
      // The pose's axes as the workbench draws them (x red, y green, z blue), projected through the lens by the core.
      const axes = m.pose && m.pose.axes;
      if (!axes) continue;
      ['#f33', '#3f3', '#57f'].forEach((colour, k) => {
        ctx.strokeStyle = colour;
        ctx.beginPath();
        ctx.moveTo(axes[0][0], axes[0][1]);
        ctx.lineTo(axes[k + 1][0], axes[k + 1][1]);
        ctx.stroke();
      });
    }
  }

  // The link of the web card drawn under a point of the window, or ''. The view shows the camera's picture scaled to
  // fit (object-fit: contain); the core's quads are in the picture's pixels.
  function webCardAt(clientX, clientY) {
    const r = view.getBoundingClientRect();
    const scale = Math.min(r.width / view.width, r.height / view.height);
    const x = (clientX - r.left - (r.width - view.width * scale) / 2) / scale - 0.5;
    const y = (clientY - r.top - (r.height - view.height * scale) / 2) / scale - 0.5;
    const inside = (c) => c.every(([ax, ay], i) => {
      const [bx, by] = c[(i + 1) % 4];
      return (bx - ax) * (y - ay) - (by - ay) * (x - ax) >= 0;
    }) || c.every(([ax, ay], i) => {
      const [bx, by] = c[(i + 1) % 4];
      return (bx - ax) * (y - ay) - (by - ay) * (x - ax) <= 0;
    });
    const hit = [...player.scene.overlays].reverse().find((o) => o.kind === 'web' && inside(o.quad.corners));
    return hit ? hit.url : '';
  }
  player.webCardAt = webCardAt;

  function drawOverlay() {
    const o = $('overlay');
    if (o.hidden) return;
    const ms = [...player.detectMs].sort((a, b) => a - b);
    const median = ms.length ? ms[Math.floor(ms.length / 2)].toFixed(1) : '-';
    const lines = [
      `${player.fps.toFixed(0)} fps drawn, ${view.width}x${view.height}, ${player.facing} camera`,
      `detect ${median} ms (median of ${ms.length})`,
      `markers: ${player.markers.map((m) => m.id).join(' ') || 'none'}`,
      `scene: ${sceneLine()}`,
      `camera: ${player.camera}`,
      `bundle: ${bundleLine()}`,
      `self-test: ${player.selfTest ? player.selfTest.text : 'not run'}`,
      `newest error: ${player.errors.length ? player.errors[player.errors.length - 1] : 'none'}`,
      ...newestWarning(),
      ...player.notes.map((n) => `note: ${n}`),
    ];
    o.textContent = lines.join('\n');
  }

  // The scene console's newest warning (a model's texture not shown, say), as the desktop's Scene panel lists it.
  function newestWarning() {
    const w = player.scene.console.filter((l) => l.level === 1).pop();
    return w ? [`newest warning: ${w.text}`] : [];
  }

  function sceneLine() {
    const s = player.scene;
    if (!s.status) return player.bundle.manifest && player.bundle.manifest.scene ? 'loading' : 'none';
    if (!s.status.ok) return `not loaded: ${s.status.error}`;
    if (!layer.gl) return `${s.status.mappings.length} mappings; media not drawn: this browser has no WebGL 2`;
    return `${s.status.mappings.length} mappings, ${s.overlays.length} media placed, ${s.drawn.length} drawn`;
  }

  function bundleLine() {
    const b = player.bundle;
    if (b.state !== 'verified') return b.state === 'none' ? 'none (this page alone)' : b.state;
    const m = b.manifest;
    return `${m.title}, ${m.dictionary} ids ${m.ids.join(' ')}, checked${b.offline ? ', kept for offline use' : ''}`;
  }

  function toggleOverlay() {
    $('overlay').hidden = !$('overlay').hidden;
    drawOverlay();
  }

  $('start').addEventListener('click', start);
  $('switch').addEventListener('click', async () => {
    player.facing = player.facing === 'environment' ? 'user' : 'environment';
    try { await openCamera(); } catch (e) { report(`the other camera did not start: ${e && e.name ? e.name : e}`); }
  });
  document.addEventListener('keydown', (e) => { if (e.key === 'd' || e.key === 'F1') toggleOverlay(); });
  $('stage').addEventListener('touchstart', (e) => { if (e.touches.length === 2) toggleOverlay(); });
  // A tap (or click) on a web card opens its link in a new tab, as a click on it does in the workbench.
  $('view').addEventListener('click', (e) => {
    const url = webCardAt(e.clientX, e.clientY);
    if (url) window.open(url, '_blank', 'noopener');
  });
  // Start waits for the page's needs and the bundle's check (which needs a secure page too).
  (async () => {
    if (!runChecks()) {
      player.bundle.state = 'unchecked';
      player.state = 'blocked';
      return;
    }
    await checkBundle();
    const b = player.bundle;
    if (b.state === 'refused') {
      player.state = 'refused';
      $('bundle').textContent = `This bundle cannot be played: ${b.problem}. Export it again, or copy all of its ` +
        'files again.';
      $('bundle').className = 'advice';
      return;
    }
    if (b.state === 'verified')
      $('bundle').textContent = `${b.manifest.ids.length} marker${b.manifest.ids.length === 1 ? '' : 's'} of ` +
        `${b.manifest.dictionary}, every file checked${b.offline ? ' and kept for offline use' : ''}. ` +
        'Its media are drawn on their markers as on the desktop.';
    else $('bundle').textContent = '';
    useBundle();
    player.state = 'ready';
    $('start').disabled = false;
  })();
})();
