// Peer check of handlabel's TFLite interpreter against TFLite's own runtime (the
// TFLite C++ interpreter compiled to wasm with XNNPACK, npm @tensorflow/tfjs-tflite)
// in headless Debian Chromium: both run MediaPipe Hands' four models on the same float
// inputs, written with our outputs by network_tests' DISABLED_WritePeerParityFiles.
//
//   node tests/network/detector/tflite_peer_parity.mjs PEER_DIR DATA_DIR MODELS_DIR [TOLERANCE]
// PEER_DIR: a folder where `npm install @tensorflow/tfjs-tflite@0.0.1-alpha.10
// @tensorflow/tfjs-core@4.9.0 @tensorflow/tfjs-backend-cpu@4.9.0` ran; playwright-core
// comes from tools/browser (scripts/install-browser-deps). Prints per model and input
// the largest absolute output difference and the peer's time per call; exits 1 when a
// difference exceeds TOLERANCE (default 1e-3). Full walk-through:
// docs/model-card-mediapipe-hands.md.
import fs from 'fs';
import http from 'http';
import {createRequire} from 'module';
import path from 'path';
import {fileURLToPath} from 'url';

const [peerDir, dataDir, modelsDir, toleranceArg] = process.argv.slice(2);
if (!peerDir || !dataDir || !modelsDir) {
  console.error('usage: tflite_peer_parity.mjs PEER_DIR DATA_DIR MODELS_DIR [TOLERANCE]');
  process.exit(2);
}
const tolerance = Number(toleranceArg || 1e-3);
const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, '../../tools/browser/package.json'));
const {chromium} = require('playwright-core');

const page_html = `<!doctype html><html><body>
<script src="/peer/node_modules/@tensorflow/tfjs-core/dist/tf-core.js"></script>
<script src="/peer/node_modules/@tensorflow/tfjs-backend-cpu/dist/tf-backend-cpu.js"></script>
<script src="/peer/node_modules/@tensorflow/tfjs-tflite/dist/tf-tflite.js"></script>
<script>
window.runPeer = async (model_name, inputs) => {
  tflite.setWasmPath('/peer/node_modules/@tensorflow/tfjs-tflite/wasm/');
  const model = await tflite.loadTFLiteModel('/models/' + model_name + '.tflite', {numThreads: 1});
  const results = {};
  for (const [name, file, size] of inputs) {
    const bytes = await (await fetch('/data/' + file)).arrayBuffer();
    const x = tf.tensor(new Float32Array(bytes), [1, size, size, 3]);
    const t0 = performance.now();
    let out = model.predict(x);
    const ms = performance.now() - t0;
    if (out instanceof tf.Tensor) out = [out];
    else if (!Array.isArray(out)) out = model.outputs.map(o => out[o.name]);
    const values = [];
    for (const o of out) values.push(...o.dataSync());
    results[name] = {values, ms};
  }
  return results;
};
</script></body></html>`;

// Serves the page, the peer packages, the data and the models from 127.0.0.1.
const roots = {'/peer/': peerDir, '/data/': dataDir, '/models/': modelsDir};
const types = {'.js': 'text/javascript', '.wasm': 'application/wasm'};
const server = http.createServer((req, res) => {
  const url = decodeURIComponent(req.url.split('?')[0]);
  if (url === '/') {
    res.writeHead(200, {'Content-Type': 'text/html'});
    res.end(page_html);
    return;
  }
  const prefix = Object.keys(roots).find(p => url.startsWith(p));
  const file = prefix && path.join(roots[prefix], path.normalize(url.slice(prefix.length)));
  fs.readFile(file || '', (err, data) => {
    if (err) {
      res.writeHead(404);
      res.end();
      return;
    }
    res.writeHead(200, {'Content-Type': types[path.extname(file)] || 'application/octet-stream'});
    res.end(data);
  });
});
await new Promise(resolve => server.listen(0, '127.0.0.1', resolve));
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu'],
});
const page = await browser.newPage();
await page.goto(`http://127.0.0.1:${server.address().port}/`);

function readFloats(file) {
  const b = fs.readFileSync(file);
  return new Float32Array(b.buffer.slice(b.byteOffset, b.byteOffset + b.length));
}

let worst = 0;
const files = fs.readdirSync(dataDir);
for (const model of ['hand_landmark_full', 'hand_landmark_lite', 'palm_detection_full',
                     'palm_detection_lite']) {
  const size = model.startsWith('hand') ? 224 : 192;
  const prefix = `in_${size}_`;
  const inputs = files.filter(f => f.startsWith(prefix))
                     .map(f => [f.slice(prefix.length, -4), f, size]);
  const results = await page.evaluate(([m, i]) => window.runPeer(m, i), [model, inputs]);
  for (const [name, peer] of Object.entries(results)) {
    const ours = readFloats(path.join(dataDir, `ours_${model}_${name}.bin`));
    if (ours.length !== peer.values.length) {
      console.log(`${model} ${name}: ${ours.length} values, peer ${peer.values.length}`);
      worst = Infinity;
      continue;
    }
    let diff = 0;
    for (let i = 0; i < ours.length; i++) diff = Math.max(diff, Math.abs(ours[i] - peer.values[i]));
    worst = Math.max(worst, diff);
    console.log(`${model} ${name}: ${ours.length} values, max |ours - peer| ${diff.toExponential(2)}, ` +
                `peer ${peer.ms.toFixed(1)} ms`);
  }
}
await browser.close();
server.close();
console.log(`worst difference ${worst.toExponential(2)} (tolerance ${tolerance})`);
process.exit(worst <= tolerance ? 0 : 1);
