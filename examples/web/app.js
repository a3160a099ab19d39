// The page's script (examples/web/README.md). Four modes, chosen by the address:
//   index.html                 the live scene, drawn with WebGL2 (controls in the header;
//                              ?n=&shape=&scene=&model=&rest=&seed= preset them)
//   index.html?check           runs hash.wasm and hash_i16.wasm (the firmware example's scenes) and
//                              shows their lines, as the host build prints them
//   index.html?bench&n=&shape=&steps=&seed=&rest=&warmup=   pours and steps without drawing, and
//                              shows one line in the format of web_demo_host (after an untimed
//                              pour of `warmup` steps, default 60, as web_demo_host does: the
//                              browser swaps its optimised code in while the first steps run)
//   index.html?drawbench&n=&shape=&steps=&frames=   the drawing's cost per frame (see drawbench)
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
  document.querySelector('main').hidden = true;
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

// ---- drawing: WebGL2, each body's mesh instanced ---------------------------------------------
// Colours of the drawing classes demo.cpp gives each body (draw_class), then the bin's walls; the
// legend in index.html names them in the same order.
const classColours = [
  [0.86, 0.30, 0.16, 1], // moving
  [0.93, 0.72, 0.18, 1], // settling
  [0.36, 0.70, 0.28, 1], // settling in a rest pose
  [0.50, 0.56, 0.68, 1], // asleep
  [0.20, 0.36, 0.72, 1], // asleep in a rest pose
  [0.60, 0.62, 0.66, 0.22], // walls
];

// The meshes are the committed OBJ files (tools/meshes) the tables were gathered from, copied
// beside the page: only their vertex and triangle lines are read. Flat shading: one normal per
// triangle, so the vertices are not shared.
function meshFromObj(text) {
  const v = [], out = [];
  for (const line of text.split('\n')) {
    const f = line.trim().split(/\s+/);
    if (f[0] === 'v') v.push([Number(f[1]), Number(f[2]), Number(f[3])]);
    else if (f[0] === 'f') {
      const idx = f.slice(1).map((t) => Number(t.split('/')[0]) - 1);
      for (let k = 1; k + 1 < idx.length; ++k) out.push([v[idx[0]], v[idx[k]], v[idx[k + 1]]]);
    }
  }
  return flatMesh(out);
}

function flatMesh(triangles) {
  const data = new Float32Array(triangles.length * 18);
  let o = 0;
  for (const [a, b, c] of triangles) {
    const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
    const l = Math.hypot(n[0], n[1], n[2]) || 1;
    for (const p of [a, b, c]) {
      data.set([p[0], p[1], p[2], n[0] / l, n[1] / l, n[2] / l], o);
      o += 6;
    }
  }
  return data;
}

// An axis-aligned box centred at the origin (half extents hx, hy, hz), counter-clockwise outside.
function boxMesh(hx, hy, hz) {
  const c = (i) => [i & 1 ? hx : -hx, i & 2 ? hy : -hy, i & 4 ? hz : -hz];
  const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
  const t = [];
  for (const [a, b, d, e] of faces) t.push([c(a), c(b), c(d)], [c(a), c(d), c(e)]);
  return flatMesh(t);
}

const meshShader = `#version 300 es
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 row0;
layout(location = 3) in vec4 row1;
layout(location = 4) in vec4 row2;
layout(location = 5) in vec4 extra;
uniform mat4 viewProjection;
uniform vec4 colours[6];
out vec3 vNormal;
out vec4 vColour;
void main() {
  vec4 p = vec4(position, 1.0);
  vec3 world = vec3(dot(row0, p), dot(row1, p), dot(row2, p));
  vNormal = vec3(dot(row0.xyz, normal), dot(row1.xyz, normal), dot(row2.xyz, normal));
  vColour = colours[int(extra.x)];
  gl_Position = viewProjection * vec4(world, 1.0);
}`;
const meshFragment = `#version 300 es
precision highp float;
in vec3 vNormal;
in vec4 vColour;
out vec4 colour;
void main() {
  vec3 n = normalize(gl_FrontFacing ? vNormal : -vNormal);
  float key = max(dot(n, normalize(vec3(0.4, -0.5, 0.85))), 0.0);
  float sky = 0.5 + 0.5 * n.z;
  colour = vec4(vColour.rgb * (0.30 + 0.25 * sky + 0.65 * key), vColour.a);
}`;
// The ground: a square at z = 0 with a 0.5 m checker that fades with distance.
const groundShader = `#version 300 es
layout(location = 0) in vec2 corner;
uniform mat4 viewProjection;
uniform float extent;
out vec2 vWorld;
void main() {
  vWorld = corner * extent;
  gl_Position = viewProjection * vec4(vWorld, 0.0, 1.0);
}`;
const groundFragment = `#version 300 es
precision highp float;
in vec2 vWorld;
uniform float extent;
out vec4 colour;
void main() {
  vec2 c = floor(vWorld * 2.0);
  float check = mod(c.x + c.y, 2.0);
  float fade = clamp(1.0 - length(vWorld) / extent, 0.0, 1.0);
  colour = vec4(mix(vec3(0.93, 0.94, 0.96), vec3(0.80 + 0.07 * check), fade), 1.0);
}`;
// Impact flashes: a ring per impact that grows and fades over its life.
const flashShader = `#version 300 es
layout(location = 0) in vec4 flash;
uniform mat4 viewProjection;
uniform float pixels;
out float vAge;
void main() {
  gl_Position = viewProjection * vec4(flash.xyz, 1.0);
  vAge = flash.w;
  gl_PointSize = pixels * (0.4 + vAge) / gl_Position.w;
}`;
const flashFragment = `#version 300 es
precision highp float;
in float vAge;
out vec4 colour;
void main() {
  float r = length(gl_PointCoord - 0.5) * 2.0;
  float ring = smoothstep(0.55, 0.8, r) * (1.0 - smoothstep(0.8, 1.0, r));
  colour = vec4(1.0, 0.95, 0.5, ring * (1.0 - vAge));
}`;

function program(gl, vs, fs) {
  const p = gl.createProgram();
  for (const [type, source] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

// Column-major 4x4 products and the camera: an orbit about a target, yaw and pitch in radians.
function multiply(a, b) {
  const r = new Float32Array(16);
  for (let i = 0; i < 4; ++i)
    for (let j = 0; j < 4; ++j) {
      let s = 0;
      for (let k = 0; k < 4; ++k) s += a[k * 4 + j] * b[i * 4 + k];
      r[i * 4 + j] = s;
    }
  return r;
}

function cameraFrame(cam) {
  const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch), cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
  const back = [cp * cy, cp * sy, sp];
  const eye = back.map((b, i) => cam.target[i] + cam.distance * b);
  const forward = back.map((b) => -b);
  const right = [-sy, cy, 0];
  const up = [right[1] * forward[2] - right[2] * forward[1], right[2] * forward[0] - right[0] * forward[2],
              right[0] * forward[1] - right[1] * forward[0]];
  return { eye, forward, right, up };
}

function viewProjection(cam, aspect) {
  const { eye, forward, right, up } = cameraFrame(cam);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const view = new Float32Array([right[0], up[0], -forward[0], 0, right[1], up[1], -forward[1], 0,
                                 right[2], up[2], -forward[2], 0, -dot(right, eye), -dot(up, eye), dot(forward, eye), 1]);
  const f = 1 / Math.tan(cam.fov / 2), near = cam.distance / 100, far = cam.distance * 20;
  const proj = new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
                                 0, 0, (2 * far * near) / (near - far), 0]);
  return multiply(proj, view);
}

class Renderer {
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl2', { antialias: !params.has('noaa') });
    if (!gl) throw new Error('WebGL2 is not available');
    this.gl = gl;
    this.meshProgram = program(gl, meshShader, meshFragment);
    this.groundProgram = program(gl, groundShader, groundFragment);
    this.flashProgram = program(gl, flashShader, flashFragment);
    this.uniforms = {};
    for (const [name, p] of [['mesh', this.meshProgram], ['ground', this.groundProgram], ['flash', this.flashProgram]])
      for (const u of ['viewProjection', 'colours', 'extent', 'pixels']) this.uniforms[name + '.' + u] = gl.getUniformLocation(p, u);
    this.instances = gl.createBuffer();
    this.wallInstances = gl.createBuffer();
    this.flashBuffer = gl.createBuffer();
    this.groundBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, this.groundBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
    this.walls = 0;
    this.wallVao = null;
  }

  // A vertex array of `mesh` (x, y, z, normal per vertex) drawn once per instance of `instances`
  // (16 floats each: three rows of the model matrix, then the drawing class).
  meshVao(mesh, instances) {
    const gl = this.gl;
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const vertices = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, vertices);
    gl.bufferData(gl.ARRAY_BUFFER, mesh, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 24, 0);
    gl.enableVertexAttribArray(1);
    gl.vertexAttribPointer(1, 3, gl.FLOAT, false, 24, 12);
    gl.bindBuffer(gl.ARRAY_BUFFER, instances);
    for (let k = 0; k < 4; ++k) {
      gl.enableVertexAttribArray(2 + k);
      gl.vertexAttribPointer(2 + k, 4, gl.FLOAT, false, 64, 16 * k);
      gl.vertexAttribDivisor(2 + k, 1);
    }
    gl.bindVertexArray(null);
    return { vao, count: mesh.length / 6 };
  }

  setMesh(mesh) {
    this.body = this.meshVao(mesh, this.instances);
    if (!this.box) this.box = this.meshVao(boxMesh(0.5, 0.5, 0.5), this.wallInstances);
  }

  // Walls as boxes: each [cx, cy, cz, hx, hy, hz].
  setWalls(boxes) {
    const data = new Float32Array(16 * boxes.length);
    boxes.forEach(([x, y, z, hx, hy, hz], i) => data.set([2 * hx, 0, 0, x, 0, 2 * hy, 0, y, 0, 0, 2 * hz, z, 5, 0, 0, 0], 16 * i));
    const gl = this.gl;
    gl.bindBuffer(gl.ARRAY_BUFFER, this.wallInstances);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    this.walls = boxes.length;
  }

  draw(cam, transforms, count, flashes, groundExtent) {
    const gl = this.gl, canvas = this.canvas;
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.93, 0.94, 0.96, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.disable(gl.CULL_FACE);
    const vp = viewProjection(cam, canvas.width / Math.max(1, canvas.height));

    gl.useProgram(this.groundProgram);
    gl.uniformMatrix4fv(this.uniforms['ground.viewProjection'], false, vp);
    gl.uniform1f(this.uniforms['ground.extent'], groundExtent);
    gl.bindVertexArray(null);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.groundBuffer);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
    gl.disableVertexAttribArray(0);

    gl.useProgram(this.meshProgram);
    gl.uniformMatrix4fv(this.uniforms['mesh.viewProjection'], false, vp);
    gl.uniform4fv(this.uniforms['mesh.colours'], classColours.flat());
    gl.bindBuffer(gl.ARRAY_BUFFER, this.instances);
    gl.bufferData(gl.ARRAY_BUFFER, transforms, gl.DYNAMIC_DRAW, 0, 16 * count);
    gl.bindVertexArray(this.body.vao);
    gl.drawArraysInstanced(gl.TRIANGLES, 0, this.body.count, count);

    gl.enable(gl.BLEND);
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
    gl.depthMask(false);
    if (this.walls) {
      gl.bindVertexArray(this.box.vao);
      gl.drawArraysInstanced(gl.TRIANGLES, 0, this.box.count, this.walls);
    }
    gl.bindVertexArray(null);
    if (flashes.length) {
      gl.useProgram(this.flashProgram);
      gl.uniformMatrix4fv(this.uniforms['flash.viewProjection'], false, vp);
      gl.uniform1f(this.uniforms['flash.pixels'], 0.25 * canvas.height);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.flashBuffer);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(flashes.flat()), gl.DYNAMIC_DRAW);
      gl.enableVertexAttribArray(0);
      gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 0, 0);
      gl.drawArrays(gl.POINTS, 0, flashes.length);
      gl.disableVertexAttribArray(0);
    }
    gl.depthMask(true);
    gl.disable(gl.BLEND);
  }
}

async function loadMeshes() {
  const meshes = [];
  for (const file of ['bunny_low.obj', 'box.obj', 'lshape.obj']) {
    const response = await fetch(file);
    if (!response.ok) throw new Error(`${file}: HTTP ${response.status}`);
    meshes.push(meshFromObj(await response.text()));
  }
  // The 2D square (1 m) as a polygon extruded 0.4 m towards the viewer (demo.cpp draws the plane's
  // x, y as x, z).
  meshes.push(boxMesh(0.5, 0.2, 0.5));
  return meshes;
}

// The scene's extent, m: what the camera frames and the ground covers.
function sceneSpread(shape, count) {
  return shape === 3 ? 0.6 * Math.sqrt(count) + 1 : Math.max(1, 0.1 * Math.sqrt(count) + 0.4);
}

function defaultCamera(shape, count) {
  const spread = sceneSpread(shape, count);
  if (shape === 3) {
    const height = Math.max(4, (1.2 * count) / spread) * 0.5;
    return { yaw: -Math.PI / 2, pitch: 0.08, distance: 1.9 * Math.max(spread, height), target: [0, 0, 0.45 * height], fov: 0.8 };
  }
  return { yaw: -0.9, pitch: 0.62, distance: 2.0 * spread, target: [0, 0, 0], fov: 0.8 };
}

// ---- ?drawbench: the drawing's cost per frame, after a pour ------------------------------------
//   index.html?drawbench&n=&shape=&steps=&frames=   pours n bodies, steps `steps` times (timed),
//   then draws `frames` frames, each closed by gl.finish(), and shows one line
async function drawbench() {
  const demo = await instantiate('statsim.wasm', {});
  const meshes = await loadMeshes();
  const shape = Math.max(0, shapeNames.indexOf(params.get('shape') || 'bunny'));
  const n = Number(params.get('n') || 1000);
  const steps = Number(params.get('steps') || 300);
  const frames = Number(params.get('frames') || 30);
  const canvas = document.getElementById('view');
  const ratio = window.devicePixelRatio || 1;
  canvas.width = Math.round(canvas.clientWidth * ratio);
  canvas.height = Math.round(canvas.clientHeight * ratio);
  const renderer = new Renderer(canvas);
  renderer.setMesh(meshes[shape]);
  if (demo.demo_reset(shape, n, 1, 1) !== 0) throw new Error('demo_reset failed');
  const t0 = performance.now();
  if (demo.demo_step(steps) !== 0) throw new Error('demo_step failed');
  const stepMs = (performance.now() - t0) / Math.max(1, steps);
  const cam = defaultCamera(shape, n);
  const spread = sceneSpread(shape, n);
  const pixel = new Uint8Array(4);
  const draw = () => {
    const pointer = demo.demo_transforms();
    const count = demo.demo_drawn();
    renderer.draw(cam, new Float32Array(demo.memory.buffer, pointer, 16 * count), count, [], 4 * spread);
    // gl.finish() returns before the GPU process has drawn; reading a pixel waits for it.
    renderer.gl.readPixels(0, 0, 1, 1, renderer.gl.RGBA, renderer.gl.UNSIGNED_BYTE, pixel);
  };
  draw();
  const t1 = performance.now();
  for (let i = 0; i < frames; ++i) draw();
  const drawMs = (performance.now() - t1) / frames;
  show(`web_draw ${shapeNames[shape]} bodies ${demo.demo_drawn()} canvas ${canvas.width}x${canvas.height} ` +
       `steps ${steps} ms_per_step ${stepMs.toFixed(3)} frames ${frames} ms_per_frame ${drawMs.toFixed(2)}\n`);
}

// ---- the live scene --------------------------------------------------------------------------
async function live() {
  const demo = await instantiate('statsim.wasm', {});
  const meshes = await loadMeshes();
  const canvas = document.getElementById('view');
  const renderer = new Renderer(canvas);
  const $ = (id) => document.getElementById(id);
  const controls = { count: $('count'), shape: $('shape'), scene: $('scene'), model: $('model'), rest: $('rest'), seed: $('seed') };
  if (params.has('n')) controls.count.value = params.get('n');
  if (params.has('shape')) controls.shape.value = String(Math.max(0, shapeNames.indexOf(params.get('shape'))));
  if (params.has('scene')) controls.scene.value = String(Math.max(0, ['pour', 'bin', 'column', 'heap'].indexOf(params.get('scene'))));
  if (params.has('model')) controls.model.value = params.get('model') === 'spheres' ? '1' : '0';
  if (params.has('rest')) controls.rest.checked = params.get('rest') !== '0';
  if (params.has('seed')) controls.seed.value = params.get('seed');
  // What a test or a screenshot reads.
  const state = (window.statsim = { steps: 0, msPerStep: 0, drawMs: 0, flashes: 0, kicks: 0, paused: false });
  let shape = 0, count = 0, times = [], drawTimes = [], flashes = [], cam = null;

  const hashText = () => {
    const hex = (v) => (v >>> 0).toString(16).padStart(8, '0');
    return '0x' + hex(demo.demo_hash_high()) + hex(demo.demo_hash_low());
  };
  function readout() {
    $('readout').textContent = `${state.msPerStep.toFixed(2)} ms per step · ${state.drawMs.toFixed(1)} ms per frame in draw calls · ` +
                               `${demo.demo_asleep() - demo.demo_waiting()} asleep · ` +
                               (demo.demo_waiting() ? `${demo.demo_waiting()} waiting for the nozzle · ` : '') +
                               `${(state.steps / 60).toFixed(1)} s`;
    $('bodies').textContent = String(demo.demo_live_count());
    $('hash').textContent = hashText();
  }

  function reset() {
    count = Math.min(10000, Math.max(1, Math.floor(Number(controls.count.value) || 1)));
    controls.count.value = count;
    shape = Number(controls.shape.value);
    demo.demo_configure(Number(controls.scene.value), Number(controls.model.value));
    const status = demo.demo_reset(shape, count, controls.rest.checked ? 1 : 0, Number(controls.seed.value) >>> 0);
    if (status !== 0) console.error(`demo_reset failed (${status})`);
    renderer.setMesh(meshes[shape]);
    cam = defaultCamera(shape, count);
    state.steps = 0;
    times = [];
    flashes = [];
    $('saved').textContent = $('restored').textContent = '';
    const scene = Number(controls.scene.value), r = demo.demo_body_size();
    if (shape === 3) {
      const half = 0.6 * Math.sqrt(count) + 1, h = Math.max(8, (1.2 * count) / half);
      renderer.setWalls([[-half - 0.1, 0, h / 2, 0.1, 0.3, h / 2], [half + 0.1, 0, h / 2, 0.1, 0.3, h / 2]]);
    } else if (scene === 1) {
      // demo.cpp's bin: cells of 2.2 r, at least eight layers' worth per row.
      let cells = 3;
      while (cells * cells * 8 < count) ++cells;
      const half = 0.5 * 2.2 * r * cells, h = 2.2 * r * 4;
      renderer.setWalls([[-half - 0.01, 0, h / 2, 0.01, half, h / 2], [half + 0.01, 0, h / 2, 0.01, half, h / 2],
                         [0, -half - 0.01, h / 2, half, 0.01, h / 2], [0, half + 0.01, h / 2, half, 0.01, h / 2]]);
    } else renderer.setWalls([]);
    readout();
  }
  $('reset').addEventListener('click', reset);
  for (const c of Object.values(controls)) c.addEventListener('change', reset);

  $('pause').addEventListener('click', () => {
    state.paused = !state.paused;
    $('pause').textContent = state.paused ? 'run' : 'pause';
  });
  // One second of steps at once (while paused: a fixed number of steps, whatever the frame rate).
  $('advance').addEventListener('click', () => {
    const status = demo.demo_step(60);
    if (status !== 0) console.error(`demo_step failed (${status})`);
    state.steps += 60;
    readout();
  });
  // Snapshots: the state hash when saved, and after the restore (equal when it is bit for bit).
  $('save').addEventListener('click', () => {
    const status = demo.demo_save();
    if (status !== 0) console.error(`demo_save failed (${status})`);
    $('saved').textContent = `saved ${hashText()} (${demo.demo_snapshot_bytes()} B)`;
    $('restored').textContent = '';
  });
  $('restore').addEventListener('click', () => {
    const before = hashText();
    const status = demo.demo_restore();
    if (status !== 0) {
      $('restored').textContent = `nothing to restore (${status})`;
      return;
    }
    state.steps = Math.max(0, state.steps);
    $('restored').textContent = `restored ${hashText()} (was ${before})`;
    readout();
  });
  $('spawn').addEventListener('click', () => {
    demo.demo_spawn(100);
    readout();
  });
  $('remove').addEventListener('click', () => {
    demo.demo_remove(100);
    readout();
  });

  function resize() {
    const ratio = window.devicePixelRatio || 1;
    canvas.width = Math.round(canvas.clientWidth * ratio);
    canvas.height = Math.round(canvas.clientHeight * ratio);
  }

  // The ray through a point of the canvas (CSS pixels), from the camera's eye.
  function rayAt(x, y) {
    const { eye, forward, right, up } = cameraFrame(cam);
    const t = Math.tan(cam.fov / 2), aspect = canvas.clientWidth / Math.max(1, canvas.clientHeight);
    const nx = (2 * x) / canvas.clientWidth - 1, ny = 1 - (2 * y) / canvas.clientHeight;
    const d = [0, 1, 2].map((i) => forward[i] + nx * t * aspect * right[i] + ny * t * up[i]);
    return { eye, d };
  }
  // The canvas point (CSS pixels) where a world point is drawn.
  state.screenOf = (p) => {
    const vp = viewProjection(cam, canvas.width / Math.max(1, canvas.height));
    const c = [0, 1, 2, 3].map((r) => vp[r] * p[0] + vp[4 + r] * p[1] + vp[8 + r] * p[2] + vp[12 + r]);
    return [(0.5 + (0.5 * c[0]) / c[3]) * canvas.clientWidth, (0.5 - (0.5 * c[1]) / c[3]) * canvas.clientHeight];
  };
  // Where the k-th drawn body is drawn (its mesh's origin, the centre of mass of the committed meshes).
  state.bodyOnScreen = (k) => {
    const t = new Float32Array(demo.memory.buffer, demo.demo_transforms(), 16 * demo.demo_drawn());
    return state.screenOf([t[16 * k + 3], t[16 * k + 7], t[16 * k + 11]]);
  };

  // Mouse: drag to orbit, wheel to zoom, click (no drag) to kick the body under the pointer.
  let drag = null;
  canvas.addEventListener('mousedown', (e) => (drag = { x: e.clientX, y: e.clientY, moved: false }));
  window.addEventListener('mouseup', (e) => {
    if (drag && !drag.moved) {
      const rect = canvas.getBoundingClientRect();
      const { eye, d } = rayAt(e.clientX - rect.left, e.clientY - rect.top);
      const kicked = demo.demo_kick(eye[0], eye[1], eye[2], d[0], d[1], d[2], shape === 3 ? 6 : 3);
      if (kicked === 0) ++state.kicks;
      else if (kicked < -1) console.error(`demo_kick refused (${kicked})`);
      readout();
    }
    drag = null;
  });
  window.addEventListener('mousemove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (!drag.moved && Math.hypot(dx, dy) < 4) return;
    drag.moved = true;
    drag.x = e.clientX;
    drag.y = e.clientY;
    cam.yaw -= dx * 0.008;
    cam.pitch = Math.min(1.5, Math.max(-0.05, cam.pitch + dy * 0.008));
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    cam.distance *= Math.exp(0.001 * e.deltaY);
  }, { passive: false });

  function draw() {
    const t0 = performance.now();
    const pointer = demo.demo_transforms();
    const drawn = demo.demo_drawn();
    const t = new Float32Array(demo.memory.buffer, pointer, 16 * drawn);
    renderer.draw(cam, t, drawn, flashes, 4 * sceneSpread(shape, count));
    return performance.now() - t0;
  }

  // A test's view of the canvas: drawn now and read back (the drawing buffer is not kept between
  // frames), as the share of pixels in the bodies' saturated colours and a coarse grid of colours.
  state.capture = () => {
    draw();
    const gl = renderer.gl, w = canvas.width, h = canvas.height;
    const px = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let saturated = 0;
    for (let i = 0; i < px.length; i += 4) {
      const max = Math.max(px[i], px[i + 1], px[i + 2]), min = Math.min(px[i], px[i + 1], px[i + 2]);
      if (max - min > 40) ++saturated;
    }
    const grid = [];
    for (let y = 0; y < h; y += 8) for (let x = 0; x < w; x += 8) grid.push(px.subarray(4 * (y * w + x), 4 * (y * w + x) + 3).join(','));
    return { saturated: saturated / (w * h), grid };
  };

  function frame() {
    if (!state.paused) {
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
      // Impacts faster than 1.5 m/s flash where they happened.
      const impacts = demo.demo_impacts();
      const e = new Float32Array(demo.memory.buffer, demo.demo_impact_buffer(), 4 * impacts);
      for (let i = 0; i < impacts; ++i)
        if (e[4 * i + 3] > 1.5 && flashes.length < 256) flashes.push([e[4 * i], e[4 * i + 1], e[4 * i + 2], 0]);
      for (const f of flashes) f[3] += 1 / 24;
      flashes = flashes.filter((f) => f[3] < 1);
    }
    if (canvas.width !== Math.round(canvas.clientWidth * (window.devicePixelRatio || 1))) resize();
    drawTimes.push(draw());
    state.flashes += flashes.length;  // rings drawn, for the test
    if (drawTimes.length > 60) drawTimes.shift();
    state.drawMs = drawTimes.reduce((a, b) => a + b, 0) / drawTimes.length;
    if (!state.paused || state.steps % 10 === 0) readout();
    requestAnimationFrame(frame);
  }
  resize();
  reset();
  requestAnimationFrame(frame);
}

const mode = params.has('check') ? check : params.has('bench') ? bench : params.has('drawbench') ? drawbench : live;
mode().catch((error) => {
  console.error(String(error && error.stack ? error.stack : error));
  show(`error: ${error}`);
});
