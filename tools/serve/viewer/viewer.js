// The LIT-GS viewer: the server renders every view (POST /render, float32 planes), this page colours them,
// navigates, and shows values. URL parameters (all optional):
//   q=w,x,y,z t=x,y,z   start camera, world-to-camera (T_cam_world), in the server's pose frame
//   fx= fy= cx= cy=     intrinsics in pixels (default: 60 degree vertical field of view)
//   w= h=               render size (default 640x512)   camera=I   start at scene camera I (default: the
//                       scene's first camera where there is a scene, else a view of the model's bounds)
//   show=image|depth|alpha  palette=gray|ironbow  range=lo,hi  mode=orbit|fly  up=x,y,z  model=NAME
//   nav=orbit:DX,DY | fly:DX,DY | move:F   one navigation step (as a drag of DX,DY pixels, or F metres
//   forward) applied before the first render
'use strict';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const numbers = (text) => (text ? text.split(',').map(Number) : null);

function reportError(message) {
  $('errors').textContent += message + '\n';
  console.error(message);
}
window.addEventListener('error', (e) => reportError('error: ' + e.message));
window.addEventListener('unhandledrejection', (e) => reportError('error: ' + (e.reason && e.reason.message || e.reason)));

// --- small vector algebra (3-vectors as arrays; R as three rows = the camera's x, y, z axes in world) ---
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));
// Rodrigues: v rotated by angle about unit axis k.
const rotate = (v, k, angle) => {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
};
function quatToRows(q) {
  const n = Math.hypot(q[0], q[1], q[2], q[3]);
  const [w, x, y, z] = q.map((v) => v / n);
  return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
          [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
          [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]];
}
function rowsToQuat(R) {
  const tr = R[0][0] + R[1][1] + R[2][2];
  let w, x, y, z;
  if (tr > 0) {
    const s = Math.sqrt(tr + 1) * 2;
    w = s / 4; x = (R[2][1] - R[1][2]) / s; y = (R[0][2] - R[2][0]) / s; z = (R[1][0] - R[0][1]) / s;
  } else if (R[0][0] > R[1][1] && R[0][0] > R[2][2]) {
    const s = Math.sqrt(1 + R[0][0] - R[1][1] - R[2][2]) * 2;
    w = (R[2][1] - R[1][2]) / s; x = s / 4; y = (R[0][1] + R[1][0]) / s; z = (R[0][2] + R[2][0]) / s;
  } else if (R[1][1] > R[2][2]) {
    const s = Math.sqrt(1 + R[1][1] - R[0][0] - R[2][2]) * 2;
    w = (R[0][2] - R[2][0]) / s; x = (R[0][1] + R[1][0]) / s; y = s / 4; z = (R[1][2] + R[2][1]) / s;
  } else {
    const s = Math.sqrt(1 + R[2][2] - R[0][0] - R[1][1]) * 2;
    w = (R[1][0] - R[0][1]) / s; x = (R[0][2] + R[2][0]) / s; y = (R[1][2] + R[2][1]) / s; z = s / 4;
  }
  const n = Math.hypot(w, x, y, z);
  return [w / n, x / n, y / n, z / n];
}

// --- state ---
const state = {
  model: params.get('model') || 'default',
  width: Number(params.get('w')) || 640,
  height: Number(params.get('h')) || 512,
  K: null,                 // {fx, fy, cx, cy} at full size
  axes: null,              // camera x, y, z axes in world (rows of R_cam_world)
  centre: null,            // camera centre in world
  pivotDistance: 1,        // orbit: distance from the camera to the point it turns around
  up: [0, 0, 1],
  palettes: {},
  data: null,              // the last render's planes
  frames: 0,
  inFlight: false,
  dirty: false,
  lastMove: 0,
};

function cameraPose() {
  const t = state.axes.map((row) => -dot(row, state.centre));
  return { q: rowsToQuat(state.axes), t };
}
function setPose(q, t) {
  state.axes = quatToRows(q);
  const R = state.axes;  // centre = -R^T t
  state.centre = [0, 1, 2].map((j) => -(R[0][j] * t[0] + R[1][j] * t[1] + R[2][j] * t[2]));
}
function defaultIntrinsics(w, h) {
  const f = 0.5 * h / Math.tan(30 * Math.PI / 180);
  return { fx: f, fy: f, cx: w / 2, cy: h / 2 };
}

// --- navigation: one function per gesture, used by the mouse, the keys and the nav= URL parameter ---
function turnAbout(pivot, yaw, pitch) {
  const right = state.axes[0];
  let axes = state.axes.map((a) => rotate(rotate(a, state.up, yaw), unit(rotate(right, state.up, yaw)), pitch));
  const rel = rotate(rotate(sub(state.centre, pivot), state.up, yaw), unit(rotate(right, state.up, yaw)), pitch);
  // Keep the axes orthonormal against drift.
  const z = unit(axes[2]), x = unit(cross(axes[1], z));
  axes = [x, cross(z, x), z];
  state.axes = axes;
  state.centre = add(pivot, rel);
}
function orbit(dx, dy) {
  const pivot = add(state.centre, scale(state.axes[2], state.pivotDistance));
  turnAbout(pivot, -dx * 0.006, dy * 0.006);
}
function look(dx, dy) { turnAbout(state.centre, -dx * 0.004, dy * 0.004); }
function move(forward, right = 0, up = 0) {
  state.centre = add(state.centre, add(add(scale(state.axes[2], forward), scale(state.axes[0], right)),
                                       scale(state.axes[1], -up)));
}
function zoom(steps) {
  const factor = Math.pow(1.15, steps);
  if (mode() === 'orbit') {
    const d = state.pivotDistance * factor;
    move(state.pivotDistance - d);
    state.pivotDistance = d;
  } else {
    move(-steps * 0.1 * state.pivotDistance);
  }
}
const mode = () => document.querySelector('input[name=mode]:checked').value;
const show = () => document.querySelector('input[name=show]:checked').value;

// --- rendering ---
function decode(output) {
  const bytes = Uint8Array.from(atob(output.base64), (c) => c.charCodeAt(0));
  return new Float32Array(bytes.buffer);
}
async function renderNow(factor) {
  state.inFlight = true;
  const w = Math.max(1, Math.round(state.width * factor)), h = Math.max(1, Math.round(state.height * factor));
  const sx = w / state.width, sy = h / state.height, K = state.K;
  const body = {
    model: state.model, pose: { T_cam_world: cameraPose() }, width: w, height: h,
    intrinsics: { fx: K.fx * sx, fy: K.fy * sy, cx: K.cx * sx, cy: K.cy * sy },
    outputs: { image: { format: 'float32' }, depth: { format: 'float32' }, alpha: { format: 'float32' } },
  };
  const started = performance.now();
  try {
    const res = await fetch('/render', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                         body: JSON.stringify(body) });
    const reply = await res.json();
    if (!res.ok) throw new Error('render: ' + res.status + ' ' + reply.error);
    const channels = reply.outputs.image.channels;
    state.data = { w, h, channels, image: toDataUnits(decode(reply.outputs.image), channels),
                   depth: decode(reply.outputs.depth), alpha: decode(reply.outputs.alpha), full: factor === 1 };
    state.frames += 1;
    draw();
    $('status').textContent = `frame ${state.frames}: ${w}x${h} in ${(performance.now() - started).toFixed(0)} ms` +
        ` (device ${Number(res.headers.get('X-Device-Ms')).toFixed(0)} ms, model ${res.headers.get('X-Model-Version')})`;
    $('status').dataset.frames = state.frames;
    $('status').dataset.full = factor === 1 ? '1' : '0';
  } catch (e) {
    reportError(e.message);
  } finally {
    state.inFlight = false;
  }
  if (state.dirty) request();
}
// Moving: a quarter-size render; still for 250 ms: full size.
function request() {
  state.lastMove = performance.now();
  if (state.inFlight) { state.dirty = true; return; }
  state.dirty = false;
  renderNow(0.25);
  setTimeout(sharpen, 260);
}
function sharpen() {
  if (performance.now() - state.lastMove < 250) return;
  if (state.inFlight) { setTimeout(sharpen, 50); return; }
  if (!state.data || !state.data.full) renderNow(1);
}

const UNITS = { image: 'intensity (model units)', depth: 'depth (m)', alpha: 'alpha' };
// A one-channel model's intensity in the data's units (GET /model's image_units: train's stretch window).
function toDataUnits(image, channels) {
  const u = state.units;
  if (!u || channels !== 1) return image;
  for (let i = 0; i < image.length; i += 1) image[i] = u.low + image[i] * (u.high - u.low);
  return image;
}
function plane() {
  const d = state.data, s = show();
  if (s === 'image') return d.channels === 1 ? d.image : d.image.subarray(0, d.w * d.h);  // RGB: channel 0
  return s === 'depth' ? d.depth : d.alpha;
}
function range(values) {
  if (!$('auto-range').checked) return [Number($('lo').value), Number($('hi').value)];
  const seen = [];
  for (let i = 0; i < values.length; i += 1)
    if (Number.isFinite(values[i]) && state.data.alpha[i] > 0.05) seen.push(values[i]);
  if (seen.length === 0) return [0, 1];
  seen.sort((a, b) => a - b);
  const lo = seen[Math.floor(0.01 * (seen.length - 1))], hi = seen[Math.ceil(0.99 * (seen.length - 1))];
  $('lo').value = lo.toPrecision(4);
  $('hi').value = hi.toPrecision(4);
  return hi > lo ? [lo, hi] : [lo, lo + 1];
}
function draw() {
  const d = state.data;
  if (!d) return;
  const table = state.palettes[$('palette').value];
  const values = plane();
  const [lo, hi] = range(values);
  const off = document.createElement('canvas');
  off.width = d.w;
  off.height = d.h;
  const ctx = off.getContext('2d');
  const img = ctx.createImageData(d.w, d.h);
  for (let i = 0; i < d.w * d.h; i += 1) {
    const v = values[i];
    const k = Number.isFinite(v) ? Math.round(Math.min(1, Math.max(0, (v - lo) / (hi - lo))) * 255) : 0;
    const c = table[k];
    img.data[4 * i] = c[0]; img.data[4 * i + 1] = c[1]; img.data[4 * i + 2] = c[2]; img.data[4 * i + 3] = 255;
  }
  ctx.putImageData(img, 0, 0);
  const view = $('view').getContext('2d');
  view.imageSmoothingEnabled = false;
  view.drawImage(off, 0, 0, state.width, state.height);
  drawLegend(table, lo, hi);
}
function drawLegend(table, lo, hi) {
  const ctx = $('legend').getContext('2d');
  const img = ctx.createImageData(256, 1);
  for (let i = 0; i < 256; i += 1) {
    img.data.set([table[i][0], table[i][1], table[i][2], 255], 4 * i);
  }
  ctx.putImageData(img, 0, 0);
  $('legend-lo').textContent = lo.toPrecision(4);
  $('legend-hi').textContent = hi.toPrecision(4);
  $('legend-unit').textContent = UNITS[show()];
}

// --- input ---
function bindInput() {
  const view = $('view');
  let drag = null;
  view.addEventListener('mousedown', (e) => { drag = [e.clientX, e.clientY]; view.style.cursor = 'grabbing'; });
  window.addEventListener('mouseup', () => { drag = null; view.style.cursor = 'grab'; });
  view.addEventListener('mousemove', (e) => {
    showValue(e);
    if (!drag) return;
    const dx = e.clientX - drag[0], dy = e.clientY - drag[1];
    drag = [e.clientX, e.clientY];
    (mode() === 'orbit' ? orbit : look)(dx, dy);
    request();
  });
  view.addEventListener('wheel', (e) => { e.preventDefault(); zoom(Math.sign(e.deltaY)); request(); },
                        { passive: false });
  view.addEventListener('keydown', (e) => {
    const step = 0.05 * state.pivotDistance;
    const moves = { w: [step, 0, 0], s: [-step, 0, 0], a: [0, -step, 0], d: [0, step, 0], e: [0, 0, step],
                    q: [0, 0, -step] };
    if (moves[e.key]) { move(...moves[e.key]); request(); }
  });
  for (const input of document.querySelectorAll('input[name=show], #palette, #auto-range, #lo, #hi'))
    input.addEventListener('change', draw);
}
function showValue(e) {
  const d = state.data;
  if (!d) return;
  const rect = $('view').getBoundingClientRect();
  const x = Math.floor((e.clientX - rect.left) * d.w / rect.width);
  const y = Math.floor((e.clientY - rect.top) * d.h / rect.height);
  if (x < 0 || y < 0 || x >= d.w || y >= d.h) return;
  const i = y * d.w + x;
  $('cursor').textContent = `value under the cursor (${x}, ${y}): intensity ${d.image[i].toPrecision(4)}` +
      `${state.units ? ' ' + state.units.name : ''}, ` +
      `depth ${d.depth[i].toPrecision(4)} m, alpha ${d.alpha[i].toPrecision(3)}`;
}

function useSceneCamera(c) {
  state.width = c.width;
  state.height = c.height;
  state.K = c.intrinsics;
  setPose(c.pose.T_cam_world.q, c.pose.T_cam_world.t);
  $('view').width = c.width;
  $('view').height = c.height;
  $('frame').src = c.frame_url;
  $('frame').style.display = 'block';
}

async function start() {
  const [palettes, model] = await Promise.all([
    fetch('/palettes').then((r) => r.json()),
    fetch('/model?name=' + encodeURIComponent(state.model)).then(async (r) => {
      const j = await r.json();
      if (!r.ok) throw new Error('model: ' + j.error);
      return j;
    })]);
  state.palettes = palettes;
  if (model.image_units && model.image_units.source) {
    state.units = model.image_units;
    UNITS.image = `intensity (${model.image_units.name})`;
  }
  for (const name of Object.keys(palettes)) $('palette').add(new Option(name, name));
  $('palette').value = params.get('palette') || 'ironbow';
  const cameras = (model.scene && model.scene.cameras) || [];
  const lo = model.bounds.min, hi = model.bounds.max;
  const mid = scale(add(lo, hi), 0.5), extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3);
  if (params.get('up')) state.up = unit(numbers(params.get('up')));
  else if (cameras.length) {  // the scene cameras' mean "up" (-y in camera axes)
    state.up = unit(cameras.map((c) => scale(quatToRows(c.pose.T_cam_world.q)[1], -1)).reduce(add, [0, 0, 0]));
  }
  // Numbered in the text, so that every number shows (a list's own markers clip past two digits) and the
  // box above jumps to it.
  cameras.forEach((c, i) => {
    const li = document.createElement('li');
    li.id = `camera-${i}`;
    li.textContent = `${i}: ${c.image} (t = ${c.t_s.toFixed(3)} s)`;
    li.addEventListener('click', () => { useSceneCamera(c); request(); });
    $('cameras').appendChild(li);
  });
  $('camera-index').max = Math.max(cameras.length - 1, 0);
  $('camera-index').addEventListener('change', () => {
    const c = cameras[Number($('camera-index').value)];
    if (!c) return reportError(`camera: no scene camera ${$('camera-index').value} (0 to ${cameras.length - 1})`);
    useSceneCamera(c);
    request();
  });
  if (params.get('camera') !== null && cameras[Number(params.get('camera'))]) {
    useSceneCamera(cameras[Number(params.get('camera'))]);
  } else if (params.get('q') && params.get('t')) {
    setPose(numbers(params.get('q')), numbers(params.get('t')));
  } else if (cameras.length) {  // where the recording started: the model as its first frame saw it
    useSceneCamera(cameras[0]);
  } else {  // looking at the model from outside its bounds
    const eye = add(mid, [1.2 * extent, 0.3 * extent, 0.5 * extent]);
    const z = unit(sub(mid, eye)), x = unit(cross(z, state.up));
    state.axes = [x, cross(z, x), z];
    state.centre = eye;
  }
  if (!state.K) {
    state.K = params.get('fx') ? { fx: Number(params.get('fx')), fy: Number(params.get('fy')),
                                   cx: Number(params.get('cx')), cy: Number(params.get('cy')) }
                               : defaultIntrinsics(state.width, state.height);
  }
  $('view').width = state.width;
  $('view').height = state.height;
  // Orbit around the model's centre as seen along the view direction.
  state.pivotDistance = Math.max(0.05 * extent, dot(sub(mid, state.centre), state.axes[2]));
  if (params.get('mode')) document.querySelector(`input[name=mode][value=${params.get('mode')}]`).checked = true;
  if (params.get('show')) document.querySelector(`input[name=show][value=${params.get('show')}]`).checked = true;
  if (params.get('range')) {
    const [a, b] = numbers(params.get('range'));
    $('auto-range').checked = false;
    $('lo').value = a;
    $('hi').value = b;
  }
  const nav = params.get('nav');
  if (nav) {
    const [kind, args] = nav.split(':');
    const v = numbers(args);
    if (kind === 'orbit') orbit(v[0], v[1]);
    else if (kind === 'fly') look(v[0], v[1]);
    else if (kind === 'move') move(v[0]);
    else reportError('nav: unknown step ' + kind);
  }
  bindInput();
  await renderNow(1);
}

start().catch((e) => reportError(e.message));
