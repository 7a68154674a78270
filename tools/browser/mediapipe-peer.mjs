// MediaPipe Hands' own runtime (the npm package's JavaScript solution in headless Debian
// Chromium) as the parity peer of handlabel's detector (network/detector/mediapipe_hands.h).
//
//   node tools/browser/mediapipe-peer.mjs --out DIR [--model full|lite] [--max-hands N]
//        [--inference gpu|cpu] IMAGE...
//
// --inference: where the solution runs the TFLite models: `gpu` (its default on desktop:
// WebGL, here SwiftShader, reduced float precision) or `cpu` (its wasm TFLite runtime,
// float32; the solution's own useCpuInference option). Image preprocessing (crops) is
// WebGL either way.
//
// Writes DIR/<index>.json per image (index = position on the command line, 0-based) and
// DIR/summary.json. Per image: the image size, the wall time of `send` (ms), and per hand
// the landmarks (normalised to the image with MediaPipe's relative z, and in pixels with
// the top-left pixel's centre at (0, 0)), the world landmarks
// (metres), handedness {label, score} as the solution reports it (selfie convention), and
// the intermediate results the solution does not expose but its graph computes: the palm
// detections (box and 7 keypoints, normalised to the image; score) and the hand ROIs made
// from them (normalised centre, size, rotation in radians). These are read by observing the
// graph's internal streams: the solution's hands.js is served with two more streams in its
// listener (nothing else changes). The hand presence score is not reachable this way (it
// lives inside the graph's per-hand loop), so only its thresholded outcome (a hand is
// reported or not) can be compared.
//
// The package folder and the images are served from 127.0.0.1 on a free port; Chromium
// runs with SwiftShader WebGL (flags from /work/shared/mediapipe-notes.md). Every image
// goes through reset() first, so each one starts with palm detection, as a static image.
import { chromium } from 'playwright-core';
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const packageDir = path.join(here, 'node_modules', '@mediapipe', 'hands');
const chromiumArgs = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-gl=swiftshader', '--enable-unsafe-swiftshader',
];
// Internal streams of the expanded graph (subgraph HandLandmarkTrackingGpu's outputs that
// the solution's top-level graph leaves unconnected, so they keep the subgraph prefix).
const palmStream = 'handlandmarktrackinggpu__palm_detections';
const roiStream = 'handlandmarktrackinggpu__hand_rects_from_palm_detections';

function usage(message) {
  if (message) console.error(`mediapipe-peer: ${message}`);
  console.error('usage: node mediapipe-peer.mjs --out DIR [--model full|lite] ' +
                '[--max-hands N] [--inference gpu|cpu] IMAGE...');
  process.exit(2);
}

function parseArgs(argv) {
  const args = { out: null, model: 'full', maxHands: 2, inference: 'gpu', images: [] };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--out') args.out = argv[++i];
    else if (a === '--model') args.model = argv[++i];
    else if (a === '--max-hands') args.maxHands = Number(argv[++i]);
    else if (a === '--inference') args.inference = argv[++i];
    else if (a.startsWith('--')) usage(`unknown option ${a}`);
    else args.images.push(a);
  }
  if (!args.out) usage('--out is required');
  if (args.model !== 'full' && args.model !== 'lite') usage('--model: expected full or lite');
  if (args.inference !== 'gpu' && args.inference !== 'cpu') {
    usage('--inference: expected gpu or cpu');
  }
  if (!Number.isInteger(args.maxHands) || args.maxHands < 1) {
    usage('--max-hands: expected an integer >= 1');
  }
  if (args.images.length === 0) usage('no images given');
  for (const image of args.images) {
    if (!fs.existsSync(image)) usage(`${image}: no such file`);
  }
  return args;
}

// hands.js with the two internal streams added to its one listener, delivered raw
// under the result keys palmDetections (the solution's detection-list form) and palmRois
// (serialised NormalizedRect protos).
function patchedHandsJs() {
  const original = fs.readFileSync(path.join(packageDir, 'hands.js'), 'utf8');
  const wants = 'wants:["multi_hand_landmarks","multi_hand_world_landmarks",' +
                '"image_transformed","multi_handedness"]';
  const outs = 'outs:{image:"image_transformed",';
  if (!original.includes(wants) || !original.includes(outs)) {
    throw new Error('hands.js: listener layout not as expected (package version changed?)');
  }
  return original
      .replace(wants, wants.slice(0, -1) + `,"${palmStream}","${roiStream}"]`)
      .replace(outs, outs + `palmDetections:{type:"detection_list",stream:"${palmStream}"},` +
                         `palmRois:{type:"proto_list",stream:"${roiStream}"},`);
}

const contentTypes = {
  '.js': 'text/javascript', '.wasm': 'application/wasm', '.html': 'text/html',
  '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg',
};

function startServer(images) {
  const handsJs = patchedHandsJs();
  const server = http.createServer((req, res) => {
    const url = decodeURIComponent(req.url.split('?')[0]);
    let body = null;
    let type = 'application/octet-stream';
    if (url === '/' || url === '/index.html') {
      body = '<!doctype html><html><body><script src="/mp/hands.js"></script></body></html>';
      type = 'text/html';
    } else if (url === '/mp/hands.js') {
      body = handsJs;
      type = 'text/javascript';
    } else if (url.startsWith('/mp/')) {
      const file = path.join(packageDir, path.basename(url));
      if (fs.existsSync(file)) {
        body = fs.readFileSync(file);
        type = contentTypes[path.extname(file)] || type;
      }
    } else if (url.startsWith('/img/')) {
      const index = Number(url.slice(5));
      if (Number.isInteger(index) && index >= 0 && index < images.length) {
        body = fs.readFileSync(images[index]);
        type = contentTypes[path.extname(images[index]).toLowerCase()] || type;
      }
    }
    if (body === null) {
      res.writeHead(404);
      res.end();
      return;
    }
    res.writeHead(200, { 'Content-Type': type });
    res.end(body);
  });
  return new Promise((resolve) => {
    server.listen(0, '127.0.0.1', () => resolve(server));
  });
}

// Runs in the page: a protobuf wire-format reader for the ROIs (mediapipe NormalizedRect,
// delivered serialised), then MediaPipe on every image.
async function pageMain({ count, model, maxHands, inference }) {
  function readFields(bytes) {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const fields = [];
    let p = 0;
    const varint = () => {
      let value = 0;
      let shift = 0;
      for (;;) {
        const b = bytes[p++];
        value += (b & 0x7f) * 2 ** shift;
        if (b < 0x80) return value;
        shift += 7;
      }
    };
    while (p < bytes.length) {
      const key = varint();
      const field = Math.floor(key / 8);
      const wire = key & 7;
      if (wire === 0) fields.push({ field, wire, value: varint() });
      else if (wire === 5) { fields.push({ field, wire, value: view.getFloat32(p, true) }); p += 4; }
      else if (wire === 1) { fields.push({ field, wire, value: view.getFloat64(p, true) }); p += 8; }
      else if (wire === 2) {
        const n = varint();
        fields.push({ field, wire, bytes: bytes.subarray(p, p + n) });
        p += n;
      } else throw new Error(`protobuf wire type ${wire} not handled`);
    }
    return fields;
  }
  // The solution converts Detection packets to {la: box as a centre rect, ea: keypoints,
  // ba: scores}; box here as MediaPipe's relative bounding box (normalised xmin, ymin, w, h).
  function palmOf(d) {
    return {
      score: d.ba.length ? d.ba[0].score : null,
      box: { xmin: d.la.ra - d.la.width / 2, ymin: d.la.sa - d.la.height / 2,
             width: d.la.width, height: d.la.height },
      keypoints: d.ea.map((p) => [p.x, p.y]),
    };
  }
  function decodeRect(bytes) {
    const rect = { x_center: 0, y_center: 0, height: 0, width: 0, rotation: 0 };
    const names = ['', 'x_center', 'y_center', 'height', 'width', 'rotation'];
    for (const f of readFields(bytes)) if (f.field <= 5) rect[names[f.field]] = f.value;
    return rect;
  }

  const hands = new Hands({ locateFile: (f) => `/mp/${f}` });
  let latest = null;
  hands.onResults((r) => { latest = r; });
  hands.setOptions({
    maxNumHands: maxHands, modelComplexity: model === 'full' ? 1 : 0,
    minDetectionConfidence: 0.5, minTrackingConfidence: 0.5, selfieMode: false,
    useCpuInference: inference === 'cpu',
  });
  await hands.initialize();
  const outputs = [];
  for (let i = 0; i < count; ++i) {
    const img = new Image();
    img.src = `/img/${i}`;
    await img.decode();
    hands.reset();
    latest = null;
    const start = performance.now();
    await hands.send({ image: img });
    const ms = performance.now() - start;
    const r = latest || {};
    const w = img.naturalWidth;
    const h = img.naturalHeight;
    const list = r.multiHandLandmarks || [];
    outputs.push({
      width: w, height: h, time_ms: ms,
      hands: list.map((lms, k) => ({
        landmarks_norm: lms.map((p) => [p.x, p.y, p.z]),
        // handlabel's pixel convention (top-left pixel centre at 0, 0).
        landmarks_px: lms.map((p) => [p.x * w - 0.5, p.y * h - 0.5]),
        world_landmarks_m: (r.multiHandWorldLandmarks || [])[k].map((p) => [p.x, p.y, p.z]),
        handedness: (r.multiHandedness || [])[k],
      })),
      palm_detections: (r.palmDetections || []).map(palmOf),
      palm_rois: (r.palmRois || []).map(decodeRect),
    });
  }
  await hands.close();
  return outputs;
}

async function main() {
  const args = parseArgs(process.argv.slice(2));
  fs.mkdirSync(args.out, { recursive: true });
  const server = await startServer(args.images);
  const port = server.address().port;
  const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: chromiumArgs });
  try {
    const page = await browser.newPage();
    page.on('crash', () => console.error('mediapipe-peer: the page crashed'));
    page.on('pageerror', (e) => console.error(`page error: ${e.message}`));
    await page.goto(`http://127.0.0.1:${port}/`);
    const t0 = Date.now();
    const results = await page.evaluate(pageMain, {
      count: args.images.length, model: args.model, maxHands: args.maxHands,
      inference: args.inference,
    });
    const wall = (Date.now() - t0) / 1000;
    results.forEach((r, i) => {
      r.image = path.resolve(args.images[i]);
      fs.writeFileSync(path.join(args.out, `${i}.json`), JSON.stringify(r, null, 1));
    });
    const times = results.map((r) => r.time_ms);
    const summary = {
      tool: 'MediaPipe Hands JS (@mediapipe/hands) in headless Chromium',
      package_version: JSON.parse(fs.readFileSync(path.join(packageDir, 'package.json'))).version,
      chromium: browser.version(), model: args.model, max_hands: args.maxHands,
      inference: args.inference,
      images: results.map((r) => r.image), hands_found: results.map((r) => r.hands.length),
      time_ms_per_image: times, total_s_including_init: wall,
    };
    fs.writeFileSync(path.join(args.out, 'summary.json'), JSON.stringify(summary, null, 1));
    const mean = times.reduce((a, b) => a + b, 0) / times.length;
    console.log(`mediapipe-peer: ${results.length} images, mean ${mean.toFixed(1)} ms per ` +
                `image (send), ${wall.toFixed(1)} s with init; wrote ${args.out}`);
  } finally {
    await browser.close();
    server.close();
  }
}

main().catch((e) => {
  console.error(`mediapipe-peer: ${e.stack || e}`);
  process.exit(1);
});
