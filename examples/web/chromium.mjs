// Loads the built page in Debian's headless Chromium, served by a small static server started
// here on 127.0.0.1 (a free port), and prints what the page shows. Fails (exit 1) on any console
// error, uncaught page error or failed request, so a test that reads the output fails too.
//   node chromium.mjs --site BUILD/web/site --modules BUILD/web-node/node_modules MODE
// MODE:
//   --check                 index.html?check: the hash lines of the firmware example's scenes
//   --bench QUERY           index.html?bench&QUERY: one timed pour (e.g. "n=10000&shape=bunny&steps=600");
//                           may be given more than once, and with --check
//   --screenshot FILE.png [--query QUERY] [--steps K]
//                           the live page (1200 x 700) after K steps (default 240)
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
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
         '--disable-component-update', '--disable-sync'],
});
const problems = [];
let status = 0;
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
    await page.waitForFunction((k) => window.statsim && window.statsim.steps >= k, steps, { timeout });
    await page.screenshot({ path: option('--screenshot') });
    const readout = await page.textContent('#readout');
    console.log(`screenshot ${option('--screenshot')} after ${steps} steps: ${readout}`);
  } else {
    // --check, or every --bench QUERY in turn, each in a fresh load of the page.
    const queries = args.includes('--check') ? ['check'] : [];
    args.forEach((a, i) => a === '--bench' && queries.push(`bench&${args[i + 1]}`));
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
