// Runs the web build's hash programs (hash.wasm, hash_i16.wasm: the firmware example's fixed
// scenes) in Node, as app.js runs them in the page, and prints their lines. Test web_node_hash
// (compare.cmake) sets them beside the host build's.
//   node run-node.mjs --site BUILD/web/site --check
import { readFile } from 'node:fs/promises';
import path from 'node:path';

const args = process.argv.slice(2);
const site = args[args.indexOf('--site') + 1];
if (args.indexOf('--site') < 0 || !args.includes('--check')) {
  console.error('usage: node run-node.mjs --site DIR --check');
  process.exit(2);
}

for (const file of ['hash.wasm', 'hash_i16.wasm']) {
  const bytes = await readFile(path.join(site, file));
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
  ({ exports } = (await WebAssembly.instantiate(bytes, { env })).instance);
  exports._initialize();
  const status = exports.main(0, 0);
  if (status !== 0) {
    console.error(`${file}: main returned ${status}`);
    process.exit(1);
  }
}
