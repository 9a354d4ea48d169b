// Reference outputs of LighterGlue (kernels/nn/models/lighterglue/lighterglue_L3.onnx) from an independent
// runtime, onnxruntime-node (the npm registry), kept as test data for the engine's own implementation. Made
// once, from the repository's root:
//
//   /usr/bin/python3 tests/data/lighterglue/expose_scores.py /tmp/lighterglue_scores.onnx
//   npm install onnxruntime-node@1.20.1        (ONNXRUNTIME_NODE_INSTALL_CUDA=skip: the CPU runtime only)
//   node tests/data/lighterglue/make_reference.js /tmp/lighterglue_scores.onnx > tests/data/lighterglue/reference.json
//
// Inputs come from formulas the C++ test evaluates the same way (keypoint_value, descriptor_value): image 1's
// keypoints and descriptors are image 0's, shuffled, moved and perturbed, plus keypoints of its own, so
// that some pairs match and some do not. Outputs: the matches, their scores and the whole score matrix.
const ort = require('onnxruntime-node');

const N0 = 40, N1 = 48, DIM = 64;

// Image 0's keypoint i: a spiral through [-0.9, 0.9]^2 (normalized coordinates).
function keypoint0(i, c) {
  const t = 0.37 * i;
  const r = 0.9 * (0.2 + 0.8 * ((i * 7) % N0) / N0);
  return c === 0 ? r * Math.cos(t) : r * Math.sin(t) * 0.8;
}
// Image 1's keypoint j: image 0's keypoint (j * 13) % N0 moved by (0.05, -0.03) for j < N0; new ones after.
function source(j) { return (j * 13) % N0; }
function keypoint1(j, c) {
  if (j < N0) return keypoint0(source(j), c) + (c === 0 ? 0.05 : -0.03);
  return c === 0 ? -0.8 + 0.2 * (j - N0) : 0.7 - 0.15 * (j - N0);
}
// Descriptor d of image 0's keypoint i, before the L2 normalization; image 1's: the source's, perturbed.
function descriptor0(i, d) { return Math.sin(1.3 * i + 0.71 * d + 0.05 * i * d) + 0.3 * Math.cos(2.1 * d - i); }
function descriptor1(j, d) {
  if (j < N0) return descriptor0(source(j), d) + 0.25 * Math.sin(5.1 * j + 1.7 * d);
  return Math.cos(0.9 * j + 1.9 * d) + 0.2 * Math.sin(d * j);
}

function normalized_rows(n, f) {
  const out = new Float32Array(n * DIM);
  for (let i = 0; i < n; ++i) {
    let norm = 0;
    for (let d = 0; d < DIM; ++d) norm += f(i, d) ** 2;
    norm = Math.sqrt(norm);
    for (let d = 0; d < DIM; ++d) out[i * DIM + d] = f(i, d) / norm;
  }
  return out;
}

function points(n, f) {
  const out = new Float32Array(n * 2);
  for (let i = 0; i < n; ++i) for (let c = 0; c < 2; ++c) out[2 * i + c] = f(i, c);
  return out;
}

async function main() {
  const session = await ort.InferenceSession.create(process.argv[2]);
  const feeds = {
    kpts0: new ort.Tensor('float32', points(N0, keypoint0), [1, N0, 2]),
    kpts1: new ort.Tensor('float32', points(N1, keypoint1), [1, N1, 2]),
    desc0: new ort.Tensor('float32', normalized_rows(N0, descriptor0), [1, N0, DIM]),
    desc1: new ort.Tensor('float32', normalized_rows(N1, descriptor1), [1, N1, DIM]),
  };
  const out = await session.run(feeds);
  const scores = out['/net/log_assignment.2/Add_2_output_0'];
  process.stdout.write(JSON.stringify({
    made_by: 'onnxruntime-node ' + require('onnxruntime-node/package.json').version + ', make_reference.js',
    n0: N0,
    n1: N1,
    matches: Array.from(out.matches.data, Number),
    match_scores: Array.from(out.scores.data),
    scores: {dims: scores.dims, values: Array.from(scores.data)},
  }) + '\n');
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
