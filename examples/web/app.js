// The page's script (examples/web/README.md). Three modes, chosen by the address:
//   index.html                 the live scene (controls in the header; ?n=&shape=&rest=&seed= preset them)
//   index.html?check           runs hash.wasm and hash_i16.wasm (the firmware example's scenes) and
//                              shows their lines, as the host build prints them
//   index.html?bench&n=&shape=&steps=&seed=&rest=&warmup=   pours and steps without drawing, and
//                              shows one line in the format of web_demo_host (after an untimed
//                              pour of `warmup` steps, default 60, as web_demo_host does: the
//                              browser swaps its optimised code in while the first steps run)
// The .wasm files are standalone (no emscripten glue): instantiated here with the one import the
// hash programs need.
'use strict';

const params = new URLSearchParams(location.search);
const shapeNames = ['bunny', 'box', 'lshape', 'square'];

async function instantiate(file, imports) {
  const response = await fetch(file);
  if (!response.ok) throw new Error(`${file}: HTTP ${response.status}`);
  const { instance } = await WebAssembly.instantiate(await response.arrayBuffer(), imports);
  // A reactor module: _initialize runs the static constructors (the worlds).
  instance.exports._initialize();
  return instance.exports;
}

function show(text) {
  const out = document.getElementById('out');
  out.hidden = false;
  out.textContent = text;
  document.querySelector('header').hidden = true;
  document.getElementById('view').hidden = true;
}

// ---- ?check: the fixed scenes' hash lines --------------------------------------------------
async function runHashProgram(file) {
  let exports = null;
  let text = '';
  const decoder = new TextDecoder();
  const env = {
    statsim_write(address) {
      const bytes = new Uint8Array(exports.memory.buffer);
      let end = address;
      while (bytes[end] !== 0) ++end;
      text += decoder.decode(bytes.subarray(address, end));
    },
  };
  exports = await instantiate(file, { env });
  const status = exports.main(0, 0);
  if (status !== 0) throw new Error(`${file}: main returned ${status}\n${text}`);
  return text;
}

async function check() {
  let text = '';
  for (const file of ['hash.wasm', 'hash_i16.wasm']) text += await runHashProgram(file);
  show(text);
}

// ---- ?bench: time the pour without drawing -------------------------------------------------
function hashText(demo) {
  const hex = (v) => (v >>> 0).toString(16).padStart(8, '0');
  return '0x' + hex(demo.demo_hash_high()) + hex(demo.demo_hash_low());
}

async function bench() {
  const demo = await instantiate('statsim.wasm', {});
  const shape = Math.max(0, shapeNames.indexOf(params.get('shape') || 'bunny'));
  const n = Number(params.get('n') || 10000);
  const steps = Number(params.get('steps') || 600);
  const seed = Number(params.get('seed') || 1);
  const rest = params.get('rest') === '0' ? 0 : 1;
  const warmup = Number(params.get('warmup') || 60);
  if (demo.demo_reset(shape, n, rest, seed) !== 0 || demo.demo_step(warmup) !== 0) throw new Error('warm-up failed');
  const status = demo.demo_reset(shape, n, rest, seed);
  if (status !== 0) throw new Error(`demo_reset failed (${status})`);
  const t0 = performance.now();
  const stepped = demo.demo_step(steps);
  const ms = performance.now() - t0;
  if (stepped !== 0) throw new Error(`demo_step failed (${stepped})`);
  show(`web_demo ${shapeNames[shape]} bodies ${demo.demo_body_count()} steps ${steps} ` +
       `ms_per_step ${(ms / steps).toFixed(3)} asleep ${demo.demo_asleep()} hash ${hashText(demo)}\n`);
}

// ---- the live scene --------------------------------------------------------------------------
async function live() {
  const demo = await instantiate('statsim.wasm', {});
  const canvas = document.getElementById('view');
  const context = canvas.getContext('2d');
  const controls = {
    count: document.getElementById('count'),
    shape: document.getElementById('shape'),
    rest: document.getElementById('rest'),
    seed: document.getElementById('seed'),
  };
  if (params.has('n')) controls.count.value = params.get('n');
  if (params.has('shape')) controls.shape.value = String(Math.max(0, shapeNames.indexOf(params.get('shape'))));
  if (params.has('rest')) controls.rest.checked = params.get('rest') !== '0';
  if (params.has('seed')) controls.seed.value = params.get('seed');
  const readout = document.getElementById('readout');
  // What a test or a screenshot waits for.
  const state = (window.statsim = { steps: 0, msPerStep: 0 });
  let shape = 0;
  let count = 0;
  let times = [];
  let order = new Uint32Array(0);
  let depth = new Float32Array(0);

  function reset() {
    count = Math.min(10000, Math.max(1, Math.floor(Number(controls.count.value) || 1)));
    controls.count.value = count;
    shape = Number(controls.shape.value);
    const status = demo.demo_reset(shape, count, controls.rest.checked ? 1 : 0, Number(controls.seed.value) >>> 0);
    if (status !== 0) console.error(`demo_reset failed (${status})`);
    state.steps = 0;
    times = [];
    order = new Uint32Array(count);
    depth = new Float32Array(count);
  }
  document.getElementById('reset').addEventListener('click', reset);
  for (const c of Object.values(controls)) c.addEventListener('change', reset);
  reset();

  function resize() {
    const ratio = window.devicePixelRatio || 1;
    canvas.width = Math.round(canvas.clientWidth * ratio);
    canvas.height = Math.round(canvas.clientHeight * ratio);
  }

  // Colours by motion state (moving, settling, asleep); lightness from 0 to 1.
  function colour(motion, light) {
    const hue = [15, 42, 212][motion] ?? 0;
    const saturation = motion === 2 ? 35 : 85;
    return `hsl(${hue},${saturation}%,${Math.round(32 + 40 * light)}%)`;
  }

  function draw3d(t, size) {
    const w = canvas.width, h = canvas.height;
    const spread = Math.max(1, 0.1 * Math.sqrt(count) + 0.4);
    // A camera turned 35 degrees about the vertical and looking 30 degrees down at the heap.
    const yaw = 0.6, pitch = 0.52;
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    const distance = 4 * spread;
    const scale = Math.min(w, 2.1 * h) / (3 * spread);
    const target = 0.15 * spread;
    const project = (x, y, z, out) => {
      const xr = x * cy + y * sy, yr = -x * sy + y * cy, zr = z - target;
      const d = yr * cp - zr * sp;
      const k = (scale * distance) / (distance + d);
      out[0] = w / 2 + xr * k;
      out[1] = 0.5 * h - (yr * sp + zr * cp) * k;
      out[2] = d;
      out[3] = k;
    };
    const p = [0, 0, 0, 0];
    context.fillStyle = '#dcdcd6';
    context.beginPath();
    for (let i = 0; i <= 64; ++i) {
      const a = (i / 64) * 2 * Math.PI;
      project(1.2 * spread * Math.cos(a), 1.2 * spread * Math.sin(a), 0, p);
      if (i === 0) context.moveTo(p[0], p[1]);
      else context.lineTo(p[0], p[1]);
    }
    context.fill();
    for (let i = 0; i < count; ++i) {
      project(t[8 * i], t[8 * i + 1], t[8 * i + 2], p);
      depth[i] = p[2];
      order[i] = i;
    }
    order.sort((a, b) => depth[b] - depth[a]);
    const top = Math.max(0.3, 0.3 * spread);
    context.lineWidth = Math.max(1, (scale * size) / 12);
    context.strokeStyle = 'rgba(0,0,0,0.45)';
    for (const i of order) {
      const o = 8 * i;
      const x = t[o], y = t[o + 1], z = t[o + 2];
      const qx = t[o + 3], qy = t[o + 4], qz = t[o + 5], qw = t[o + 6];
      project(x, y, z, p);
      const sx = p[0], sy2 = p[1], r = Math.max(0.8, 0.7 * size * p[3]);
      if (sx < -r || sx > w + r || sy2 < -r || sy2 > h + r) continue;
      context.fillStyle = colour(t[o + 7], Math.min(1, Math.max(0, z / top)));
      context.beginPath();
      context.arc(sx, sy2, r, 0, 2 * Math.PI);
      context.fill();
      // The body's own up axis (third column of its rotation), so that turning shows.
      const ux = 2 * (qx * qz + qw * qy), uy = 2 * (qy * qz - qw * qx), uz = 1 - 2 * (qx * qx + qy * qy);
      project(x + 0.9 * size * ux, y + 0.9 * size * uy, z + 0.9 * size * uz, p);
      context.beginPath();
      context.moveTo(sx, sy2);
      context.lineTo(p[0], p[1]);
      context.stroke();
    }
  }

  function draw2d(t) {
    const w = canvas.width, h = canvas.height;
    const half = 0.6 * Math.sqrt(count) + 1;
    const scale = Math.min((0.94 * w) / (2 * half), (0.9 * h) / Math.max(4, (1.2 * count) / half));
    const X = (x) => w / 2 + x * scale, Y = (y) => 0.95 * h - y * scale;
    context.fillStyle = '#dcdcd6';
    context.fillRect(X(-half) - 4, Y(0), 2 * half * scale + 8, 0.05 * h);
    context.fillRect(X(-half) - 4, 0, 4, Y(0));
    context.fillRect(X(half), 0, 4, Y(0));
    const corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
    for (let i = 0; i < count; ++i) {
      const o = 8 * i, x = t[o], y = t[o + 1], c = t[o + 3], s = t[o + 4];
      context.fillStyle = colour(t[o + 7], 0.5);
      context.beginPath();
      for (let k = 0; k < 4; ++k) {
        const [a, b] = corners[k];
        const px = X(x + c * a - s * b), py = Y(y + s * a + c * b);
        if (k === 0) context.moveTo(px, py);
        else context.lineTo(px, py);
      }
      context.fill();
    }
  }

  function frame() {
    const t0 = performance.now();
    const status = demo.demo_step(1);
    const ms = performance.now() - t0;
    if (status !== 0) {
      console.error(`demo_step failed (${status})`);
      return;
    }
    ++state.steps;
    times.push(ms);
    if (times.length > 60) times.shift();
    state.msPerStep = times.reduce((a, b) => a + b, 0) / times.length;
    if (canvas.width !== Math.round(canvas.clientWidth * (window.devicePixelRatio || 1))) resize();
    context.clearRect(0, 0, canvas.width, canvas.height);
    const t = new Float32Array(demo.memory.buffer, demo.demo_transforms(), 8 * count);
    if (shape === 3) draw2d(t);
    else draw3d(t, demo.demo_body_size());
    readout.textContent = `${state.msPerStep.toFixed(2)} ms per step · ${demo.demo_asleep()} of ${count} asleep · ` +
                          `${(state.steps / 60).toFixed(1)} s`;
    requestAnimationFrame(frame);
  }
  resize();
  requestAnimationFrame(frame);
}

const mode = params.has('check') ? check : params.has('bench') ? bench : live;
mode().catch((error) => {
  console.error(String(error && error.stack ? error.stack : error));
  show(`error: ${error}`);
});
