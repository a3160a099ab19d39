// Runs the web build in Node as app.js runs it in the page, and prints what the page would show:
//   --check        the hash programs (hash.wasm, hash_i16.wasm: the firmware example's fixed
//                  scenes), their lines
//   --bench QUERY  statsim.wasm's pour as index.html?bench&QUERY does (shape, n, steps, seed,
//                  rest, warmup), one line in web_demo_host's format; may be given more than once
// Tests web_node_hash (compare.cmake) set these beside the host build's.
//   node run-node.mjs --site BUILD/web/site [--check] [--bench QUERY]...
import { readFile } from 'node:fs/promises';
import path from 'node:path';

const args = process.argv.slice(2);
const site = args[args.indexOf('--site') + 1];
if (args.indexOf('--site') < 0 || !(args.includes('--check') || args.includes('--bench'))) {
  console.error('usage: node run-node.mjs --site DIR [--check] [--bench QUERY]...');
  process.exit(2);
}

async function instantiate(file, imports) {
  const { instance } = await WebAssembly.instantiate(await readFile(path.join(site, file)), imports);
  instance.exports._initialize();
  return instance.exports;
}

if (args.includes('--check')) {
  for (const file of ['hash.wasm', 'hash_i16.wasm']) {
    let exports = null;
    const decoder = new TextDecoder();
    const env = {
      statsim_write(address) {
        const memory = new Uint8Array(exports.memory.buffer);
        let end = address;
        while (memory[end] !== 0) ++end;
        process.stdout.write(decoder.decode(memory.subarray(address, end)));
      },
    };
    exports = await instantiate(file, { env });
    const status = exports.main(0, 0);
    if (status !== 0) {
      console.error(`${file}: main returned ${status}`);
      process.exit(1);
    }
  }
}

const shapeNames = ['bunny', 'box', 'lshape', 'square'];
for (let i = 0; i < args.length; ++i) {
  if (args[i] !== '--bench') continue;
  const params = new URLSearchParams(args[i + 1]);
  const demo = await instantiate('statsim.wasm', {});
  const shape = Math.max(0, shapeNames.indexOf(params.get('shape') || 'bunny'));
  const n = Number(params.get('n') || 10000);
  const steps = Number(params.get('steps') || 600);
  const seed = Number(params.get('seed') || 1);
  const rest = params.get('rest') === '0' ? 0 : 1;
  const warmup = Number(params.get('warmup') || 60);
  if (demo.demo_reset(shape, n, rest, seed) !== 0 || demo.demo_step(warmup) !== 0 ||
      demo.demo_reset(shape, n, rest, seed) !== 0) {
    console.error('statsim.wasm: the pour failed');
    process.exit(1);
  }
  const t0 = performance.now();
  const status = demo.demo_step(steps);
  const ms = performance.now() - t0;
  if (status !== 0) {
    console.error(`statsim.wasm: demo_step failed (${status})`);
    process.exit(1);
  }
  const hex = (v) => (v >>> 0).toString(16).padStart(8, '0');
  console.log(`web_demo ${shapeNames[shape]} bodies ${demo.demo_body_count()} steps ${steps} ` +
              `ms_per_step ${(ms / steps).toFixed(3)} asleep ${demo.demo_asleep()} ` +
              `hash 0x${hex(demo.demo_hash_high())}${hex(demo.demo_hash_low())}`);
}
