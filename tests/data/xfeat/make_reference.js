// Reference outputs of XFeat (kernels/nn/models/xfeat/xfeat_640x640.onnx) from an independent runtime,
// onnxruntime-node (the npm registry), kept as test data for the engine's own implementation. Made once:
//
//   npm install onnxruntime-node@1.20.1        (ONNXRUNTIME_NODE_INSTALL_CUDA=skip: the CPU runtime only)
//   node tests/data/xfeat/make_reference.js > tests/data/xfeat/reference.json
//
// The exported graph takes 640x640 only. Inputs are patterns computed from a formula that the C++ test
// evaluates the same way (input_value below), normalized to zero mean and unit variance as XFeat expects.
// Outputs are sampled (every STRIDE-th element of each, in the graph's layout) to keep the file small.
const ort = require('onnxruntime-node');
const path = require('path');

const SIZE = 640;
const STRIDE = 61;

// Pattern k at pixel (x, y), before normalization: smooth gradients, oriented stripes and blobs.
function input_value(k, x, y) {
  if (k === 0) return Math.sin(0.05 * x) * Math.cos(0.031 * y) + 0.002 * x;
  return Math.sin(0.11 * (x + 0.7 * y)) + 0.5 * Math.cos(0.023 * x * (1 + 0.001 * y)) +
         (((x >> 5) + (y >> 5)) % 2 ? 0.8 : -0.3);
}

function normalized(k) {
  const n = SIZE * SIZE;
  const v = new Float64Array(n);
  let mean = 0;
  for (let y = 0; y < SIZE; ++y)
    for (let x = 0; x < SIZE; ++x) mean += (v[y * SIZE + x] = input_value(k, x, y));
  mean /= n;
  let variance = 0;
  for (let i = 0; i < n; ++i) variance += (v[i] - mean) ** 2;
  const sd = Math.sqrt(variance / n);
  const out = new Float32Array(n);
  for (let i = 0; i < n; ++i) out[i] = (v[i] - mean) / sd;
  return out;
}

async function main() {
  const model = path.join(__dirname, '../../../kernels/nn/models/xfeat/xfeat_640x640.onnx');
  const session = await ort.InferenceSession.create(model);
  const result = {
    made_by: 'onnxruntime-node ' + require('onnxruntime-node/package.json').version + ', make_reference.js',
    size: SIZE,
    stride: STRIDE,
    patterns: [],
  };
  for (const k of [0, 1]) {
    const input = new ort.Tensor('float32', normalized(k), [1, 1, SIZE, SIZE]);
    const out = await session.run({input});
    const pattern = {pattern: k, outputs: {}};
    for (const name of session.outputNames) {
      const data = out[name].data;
      const sampled = [];
      for (let i = 0; i < data.length; i += STRIDE) sampled.push(data[i]);
      pattern.outputs[name] = {dims: out[name].dims, values: sampled};
    }
    result.patterns.push(pattern);
  }
  process.stdout.write(JSON.stringify(result) + '\n');
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
