// Opens the three.js page in headless Chromium (SwiftShader WebGL) on a Sylva glTF export
// and prints one JSON report: errors the page logged, what it loaded, the draw calls of a
// frame, how far the leaf joints turn the leaves relative to their branch at several times,
// how far sample vertices move, and how many pixels change between two times (in wind mode
// also with the wind off, which must change none).
//
//   node tools/web/check.js tree.glb [--mode clip|wind] [--size 640] [--screenshot out.png]
//   node tools/web/check.js tree.glb --serve [port]     # serve the page to a browser of yours
//
// The screenshot is the canvas at the first probe time.
//
// Chromium: $CHROMIUM, else /usr/bin/chromium (Debian's `chromium` package).
// Exit status 1 when the page logs an error or cannot load the file.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const glb = args.find((a, i) => !a.startsWith('--') && !['--screenshot', '--serve', '--mode', '--size'].includes(args[i - 1]));
const shotAt = args.indexOf('--screenshot');
const screenshot = shotAt >= 0 ? args[shotAt + 1] : null;
const serveAt = args.indexOf('--serve');
const modeAt = args.indexOf('--mode');
const mode = modeAt >= 0 ? args[modeAt + 1] : null;
const sizeAt = args.indexOf('--size');
const size = sizeAt >= 0 ? Number(args[sizeAt + 1]) || 640 : 640;
if (!glb) {
  console.error('usage: node check.js FILE.glb [--screenshot out.png | --serve [port]]');
  process.exit(2);
}

const types = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary', '.json': 'application/json' };
const server = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://127.0.0.1');
  const file = url.pathname === '/tree.glb' ? path.resolve(glb) : path.join(here, path.normalize(url.pathname));
  if (!file.startsWith(here) && file !== path.resolve(glb)) { res.writeHead(403).end(); return; }
  fs.readFile(file, (err, data) => {
    if (err) { res.writeHead(404).end(); return; }
    res.writeHead(200, { 'content-type': types[path.extname(file)] ?? 'application/octet-stream' }).end(data);
  });
});
const wanted = serveAt >= 0 ? Number(args[serveAt + 1] ?? 8080) || 8080 : 0;
await new Promise((ok) => server.listen(wanted, '127.0.0.1', ok));
const port = server.address().port;
if (serveAt >= 0) {
  console.log(`open http://127.0.0.1:${port}/index.html?file=/tree.glb (Ctrl-C to stop)`);
  await new Promise(() => {});
}

const errors = [];
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--headless=new', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
    '--no-sandbox', '--disable-dev-shm-usage', `--window-size=${size},${size}`],
  defaultViewport: { width: size, height: size },
});
let report = { errors };
try {
  const page = await browser.newPage();
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page: ${e.message}`));
  page.on('requestfailed', (r) => errors.push(`request: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => { if (r.status() >= 400) errors.push(`response: ${r.url()} ${r.status()}`); });
  await page.goto(`http://127.0.0.1:${port}/index.html?file=/tree.glb&paused${mode ? `&mode=${mode}` : ''}`);
  await page.waitForFunction('window.sylva && (window.sylva.ready || window.sylva.error)', { timeout: 300_000 });
  const info = await page.evaluate(() => {
    const { probe, pixels, tick, ...rest } = window.sylva;
    return rest;
  });
  report = { ...report, ...info, probes: [] };
  if (info.ready) {
    const duration = info.mode === 'wind' ? 3 : info.clip?.duration ?? 0;
    const times = [0, duration / 3, (2 * duration) / 3];
    const frames = [];
    const render = async (t, strength = null) => {
      const p = await page.evaluate((t, k) => window.sylva.probe(t, 64, k), t, strength);
      return [p, await page.evaluate(() => Array.from(window.sylva.pixels()))];
    };
    for (const t of times) {
      const [p, px] = await render(t);
      frames.push(px);
      if (screenshot && t === times[0]) await (await page.$('canvas')).screenshot({ path: screenshot });
      const rms = Math.sqrt(p.leafTurnDeg.reduce((s, a) => s + a * a, 0) / Math.max(1, p.leafTurnDeg.length));
      report.probes.push({ t, leafTurnRmsDeg: rms, leafTurnMaxDeg: Math.max(0, ...p.leafTurnDeg), vertices: p.vertices, drawCalls: p.drawCalls });
    }
    const moved = (a, b) => {
      let changed = 0;
      for (let i = 0; i < a.length; i += 4) {
        if (Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) > 24) changed++;
      }
      return changed / (a.length / 4);
    };
    report.pixelsChanged = moved(frames[0], frames[2]);
    report.background = Array.from(frames[0].slice(0, 4));
    if (info.mode === 'wind') {
      const still = [(await render(times[0], 0))[1], (await render(times[2], 0))[1]];
      report.stillPixelsChanged = moved(still[0], still[1]);
    }
  }
} catch (e) {
  errors.push(`check: ${e.message}`);
} finally {
  await browser.close();
  server.close();
}
console.log(JSON.stringify(report));
process.exit(errors.length || !report.ready ? 1 : 0);
