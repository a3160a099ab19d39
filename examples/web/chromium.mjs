// Loads the built page in Debian's headless Chromium, served by a small static server started
// here on 127.0.0.1 (a free port), and prints what the page shows. Fails (exit 1) on any console
// error, uncaught page error or failed request, so a test that reads the output fails too.
//   node chromium.mjs --site BUILD/web/site --modules BUILD/web-node/node_modules MODE
// MODE:
//   --check                 index.html?check: the hash lines of the firmware example's scenes
//   --bench QUERY           index.html?bench&QUERY: one timed pour (e.g. "n=10000&shape=bunny&steps=600");
//                           may be given more than once, and with --check
//   --drawbench QUERY       index.html?drawbench&QUERY: the drawing's cost per frame (e.g.
//                           "n=1000&shape=bunny&steps=300&frames=30"); may be given more than once
//   --live QUERY            the live page (index.html?QUERY) driven through its own controls:
//                           its canvas read back after the first step and after --steps K (default
//                           180) must hold bodies and differ; a click on a body kicks it (the
//                           state hash changes); save, steps, restore give back the saved hash;
//                           +100 and -100 change the body count; a scene and a model switch reset
//                           the world. Prints what it saw; fails when any check fails.
//   --screenshot FILE.png [--query QUERY] [--steps K]
//                           the live page (1200 x 700) after about K steps (default 240; paused,
//                           then stepped by its "+1 s" button)
// Options: --chromium PATH (default /usr/bin/chromium), --timeout SECONDS (default 600).
// playwright-core drives Chromium over the DevTools protocol; it is installed into the build
// tree by the main build (examples/CMakeLists.txt), with no browser download.
import { createRequire } from 'node:module';
import { createServer } from 'node:http';
import { readFile } from 'node:fs/promises';
import path from 'node:path';

const args = process.argv.slice(2);
const option = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const site = option('--site');
const modules = option('--modules');
if (!site || !modules) {
  console.error('usage: node chromium.mjs --site DIR --modules NODE_MODULES (--check | --bench QUERY | --screenshot FILE)');
  process.exit(2);
}
const timeout = 1000 * Number(option('--timeout', 600));
const { chromium } = createRequire(path.join(path.resolve(modules), 'index.js'))('playwright-core');

const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm', '.png': 'image/png' };
const root = path.resolve(site);
const server = createServer(async (request, response) => {
  const name = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
  const file = path.join(root, name === '/' ? 'index.html' : name);
  if (!file.startsWith(root + path.sep)) {
    response.writeHead(403).end();
    return;
  }
  try {
    const body = await readFile(file);
    response.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' }).end(body);
  } catch {
    response.writeHead(404).end();
  }
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const base = `http://127.0.0.1:${server.address().port}/index.html`;

// As root Chromium needs --no-sandbox; the rest keep it off the network (this machine has none,
// and Chromium would keep trying) and out of first-run work. Playwright gives it a fresh
// temporary profile (--user-data-dir) on every launch.
const browser = await chromium.launch({
  executablePath: option('--chromium', '/usr/bin/chromium'),
  headless: true,
  timeout,
  // WebGL2 without a GPU: ANGLE on SwiftShader, Chromium's software renderer, which it only
  // offers WebGL on when told that its weaker sandboxing is acceptable.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic', '--no-first-run', '--disable-background-networking',
         '--disable-component-update', '--disable-sync'],
});
const problems = [];
let status = 0;

// The live page's checks (--live). Each failure is a problem: the run fails.
async function live(page, query, steps) {
  const check = (ok, what) => {
    console.log(`${ok ? 'ok' : 'FAILED'}: ${what}`);
    if (!ok) problems.push(`live check failed: ${what}`);
  };
  const stepsAtLeast = (k) => page.waitForFunction((s) => window.statsim && window.statsim.steps >= s, k, { timeout });
  const text = async (id) => (await page.textContent(`#${id}`)).trim();
  await page.goto(`${base}?${query}`);
  await stepsAtLeast(1);
  const first = await page.evaluate(() => window.statsim.capture());
  await stepsAtLeast(steps);
  const later = await page.evaluate(() => window.statsim.capture());
  let changed = 0;
  for (let i = 0; i < first.grid.length; ++i) if (first.grid[i] !== later.grid[i]) ++changed;
  const share = changed / first.grid.length;
  check(later.saturated > 0.005, `the canvas holds bodies after ${steps} steps: ${(100 * later.saturated).toFixed(1)}% of its pixels in their colours`);
  check(share > 0.01, `the canvas differs from the first frame: ${(100 * share).toFixed(1)}% of a grid of pixels changed`);
  const flashes = await page.evaluate(() => window.statsim.flashes);
  check(flashes > 0, `impacts flashed: ${flashes}`);

  // Kick: paused, a click on a body changes the state (apply_impulse wakes it and sets its velocity).
  await page.click('#pause');
  await page.waitForFunction(() => window.statsim.paused);
  const before = await text('hash');
  const box = await page.locator('#view').boundingBox();
  let kicked = false;
  for (let k = 0; k < 40 && !kicked; ++k) {
    const [x, y] = await page.evaluate((i) => window.statsim.bodyOnScreen(i), k * 7);
    if (x < 1 || y < 1 || x > box.width - 1 || y > box.height - 1) continue;
    await page.mouse.click(box.x + x, box.y + y);
    kicked = (await text('hash')) !== before;
  }
  check(kicked, `a click on a body kicks it: state hash ${before} -> ${await text('hash')}`);

  // Snapshot: save, run on, restore; the hash after the restore is the hash when saved.
  await page.click('#save');
  const saved = (await text('saved')).split(' ')[1];
  check(saved === (await text('hash')), `save shows the state hash: ${saved}`);
  await page.click('#pause');
  const at = await page.evaluate(() => window.statsim.steps);
  await stepsAtLeast(at + 30);
  await page.click('#pause');
  const moved = await text('hash');
  await page.click('#restore');
  const restored = (await text('restored')).split(' ')[1];
  check(moved !== saved && restored === saved && (await text('hash')) === saved,
        `restore gives back the saved state: saved ${saved}, 30 steps later ${moved}, restored ${restored}`);

  // Spawn and remove with the world running.
  await page.click('#pause');
  const n0 = Number(await text('bodies'));
  await page.click('#spawn');
  const n1 = Number(await text('bodies'));
  await page.click('#remove');
  await page.click('#remove');
  const n2 = Number(await text('bodies'));
  check(n1 === n0 + 100 && n2 === n1 - 200, `+100 and -100 twice: ${n0} -> ${n1} -> ${n2} bodies`);

  // Scene and model: each switch resets the world into another state; paused, one second of
  // steps (+1 s) from the same pour gives another state under the other model.
  const pourHash = await text('hash');
  await page.selectOption('#scene', '1');
  const binHash = await text('hash');
  await page.selectOption('#scene', '0');
  await page.click('#pause');
  await page.selectOption('#model', '1');
  await page.click('#advance');
  const spheres = await text('hash');
  await page.selectOption('#model', '0');
  await page.click('#advance');
  const hulls = await text('hash');
  check(binHash !== pourHash && spheres !== hulls, `scene and model switches: pour ${pourHash}, bin ${binHash}; ` +
        `1 s after the reset, collision spheres ${spheres}, hulls ${hulls}`);
  console.log(`readout: ${await text('readout')}`);
}
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 700 } });
  page.on('console', (message) => {
    if (message.type() === 'error') problems.push(`console error: ${message.text()}`);
  });
  page.on('pageerror', (error) => problems.push(`page error: ${error.message}`));
  page.on('requestfailed', (request) => problems.push(`request failed: ${request.url()}`));
  page.on('response', (response) => {
    if (response.status() >= 400) problems.push(`HTTP ${response.status()}: ${response.url()}`);
  });
  if (args.includes('--screenshot')) {
    const query = option('--query', '');
    const steps = Number(option('--steps', 240));
    await page.goto(`${base}${query ? '?' + query : ''}`);
    // Paused at once, then stepped by the page's own "+1 s" button: the software renderer draws
    // a frame in about a second, too slow to watch a pile form frame by frame.
    await page.waitForFunction(() => window.statsim && window.statsim.steps >= 1, null, { timeout });
    await page.click('#pause');
    for (let k = 1; k < steps; k += 60) await page.click('#advance');
    await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
    await page.screenshot({ path: option('--screenshot') });
    const readout = await page.textContent('#readout');
    console.log(`screenshot ${option('--screenshot')} after ${steps} steps: ${readout}`);
  } else if (args.includes('--live')) {
    await live(page, option('--live'), Number(option('--steps', 180)));
  } else {
    // --check, or every --bench and --drawbench QUERY in turn, each in a fresh load of the page.
    const queries = args.includes('--check') ? ['check'] : [];
    args.forEach((a, i) => a === '--bench' && queries.push(`bench&${args[i + 1]}`));
    args.forEach((a, i) => a === '--drawbench' && queries.push(`drawbench&${args[i + 1]}`));
    for (const query of queries) {
      await page.goto(`${base}?${query}`);
      await page.waitForFunction(() => !document.getElementById('out').hidden, null, { timeout });
      process.stdout.write(await page.textContent('#out'));
    }
  }
} catch (error) {
  problems.push(String(error));
} finally {
  await browser.close();
  server.close();
}
for (const p of problems) {
  console.error(p);
  status = 1;
}
process.exit(status);
