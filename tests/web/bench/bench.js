// The web bench's page (run.mjs serves it and reads window.benchResult): every detector on the same frames in this
// one page's main thread, each frame `repeats` times. A detector's time for a frame is the fastest of its repeats
// (as `arwb bench` keeps), and its figure the median over frames; recall is the share of the truth's markers it
// found (same id, centre within a quarter of the marker's side). Each is timed as `arwb bench` times native
// detectors, from the frame in the detector's own input to its markers: our core from the RGBA in its frame buffer
// (where the player's worker writes it), opencv.js from an RGBA cv.Mat (converted to grey), js-aruco2 from the
// ImageData.
'use strict';
(async () => {
  const params = new URLSearchParams(location.search);
  const repeats = Number(params.get('repeats') || 5);
  const truth = await (await fetch('frames/truth.jsonl')).text();
  const frames = truth.trim().split('\n').map((l) => JSON.parse(l));
  const images = [];
  for (const f of frames) {
    const bitmap = await createImageBitmap(await (await fetch(`frames/${f.file}`)).blob());
    const c = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = c.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    images.push(ctx.getImageData(0, 0, bitmap.width, bitmap.height));
  }

  // Ours.
  const m = await ArwbCore();
  const frame = m.cwrap('arwb_frame', 'number', ['number', 'number']);
  const detect = m.cwrap('arwb_detect', 'string', []);
  // Each still searched whole, as `arwb bench` searches them (the core's video mode would search around the last
  // frame's markers).
  m.cwrap('arwb_set_param', 'string', ['string', 'number'])('full_search_interval', 1);
  const ours = {
    prepare(img) { m.HEAPU8.set(img.data, frame(img.width, img.height)); },
    run: () => JSON.parse(detect()).markers.map((k) => ({ id: k.id, corners: k.corners })),
  };

  // opencv.js: its ArucoDetector with its defaults, on ARUCO_ORIGINAL.
  const ocv = cv;
  if (!ocv.Mat) await new Promise((resolve) => { ocv.onRuntimeInitialized = resolve; });
  const detector = new ocv.aruco_ArucoDetector(ocv.getPredefinedDictionary(ocv.DICT_ARUCO_ORIGINAL),
                                                new ocv.aruco_DetectorParameters(),
                                                new ocv.aruco_RefineParameters(10, 3, true));
  let rgba = null;
  const opencv = {
    prepare(img) {
      if (rgba) rgba.delete();
      rgba = ocv.matFromImageData(img);
    },
    run: () => opencvDetect(rgba),
  };
  const opencvDetect = (rgba) => {
    const grey = new ocv.Mat();
    ocv.cvtColor(rgba, grey, ocv.COLOR_RGBA2GRAY);
    const corners = new ocv.MatVector(), ids = new ocv.Mat(), rejected = new ocv.MatVector();
    detector.detectMarkers(grey, corners, ids, rejected);
    const out = [];
    for (let i = 0; i < ids.rows; i++) {
      const c = corners.get(i);
      out.push({ id: ids.data32S[i], corners: [0, 1, 2, 3].map((k) => [c.data32F[2 * k], c.data32F[2 * k + 1]]) });
      c.delete();
    }
    [grey, corners, ids, rejected].forEach((x) => x.delete());
    return out;
  };

  // js-aruco2 on its ARUCO dictionary (the original ArUco's 1024 codes).
  const jsDetector = new AR.Detector({ dictionaryName: 'ARUCO' });
  let imageData = null;
  const jsAruco = {
    prepare(img) { imageData = img; },
    run: () => jsDetector.detect(imageData).map((k) => ({ id: k.id, corners: k.corners.map((p) => [p.x, p.y]) })),
  };

  const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
  const centre = (cs) => cs.reduce(([x, y], [a, b]) => [x + a / 4, y + b / 4], [0, 0]);
  const result = { frames: images.length, repeats, isolated: crossOriginIsolated, detectors: {} };
  for (const [name, { prepare, run }] of [['arwb (WebAssembly)', ours], ['opencv.js ArucoDetector', opencv],
                                          ['js-aruco2', jsAruco]]) {
    // One untimed pass over every frame first: the engine compiles hot WebAssembly and JavaScript again with its
    // optimising tier as they run, so the first frames timed would otherwise measure the baseline compiler's code.
    for (const img of images) {
      prepare(img);
      run();
    }
    const perFrame = [];
    let found = 0, wanted = 0, extra = 0;
    images.forEach((img, i) => {
      const times = [];
      let markers = [];
      prepare(img);
      for (let r = 0; r < repeats; r++) {
        const t0 = performance.now();
        markers = run();
        times.push(performance.now() - t0);
      }
      perFrame.push(Math.min(...times));
      const truths = frames[i].markers;
      wanted += truths.length;
      const used = new Set();
      for (const t of truths) {
        const [tx, ty] = centre(t.corners);
        const side = Math.hypot(t.corners[1][0] - t.corners[0][0], t.corners[1][1] - t.corners[0][1]);
        const k = markers.findIndex((d, j) => {
          const [dx, dy] = centre(d.corners);
          return !used.has(j) && d.id === t.id && Math.hypot(dx - tx, dy - ty) < side / 4;
        });
        if (k >= 0) { used.add(k); found++; }
      }
      extra += markers.length - used.size;
    });
    result.detectors[name] = { median_ms: median(perFrame), recall: wanted ? found / wanted : NaN, found, wanted,
                               extra };
  }
  window.benchResult = result;
  document.getElementById('log').textContent = JSON.stringify(result, null, 1);
})().catch((e) => { window.benchResult = { error: String(e && e.stack ? e.stack : e) }; });
