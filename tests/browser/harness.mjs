// Shared helpers of the studio's end-to-end tests: start `cleave studio` on a session folder,
// launch Debian's chromium headless through playwright-core, take screenshots.
// Environment (set by CTest, tests/CMakeTests.cmake):
//   CLEAVE_BIN          the built `cleave` binary
//   CLEAVE_STUDIO_PORT  a port to use (0 or unset: any free port)
//   CLEAVE_SCREENSHOTS  folder for screenshots (default: build/browser-screenshots)
//   CHROMIUM            chromium binary (default /usr/bin/chromium)
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const repoRoot = path.resolve(here, '..', '..');
const webRoot = path.join(repoRoot, 'web');

export function requireTools() {
  const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
  if (!fs.existsSync(chromium)) throw new Error(`${chromium} is missing: run scripts/install-deps.sh (Debian package chromium)`);
  if (!fs.existsSync(path.join(webRoot, 'node_modules', 'playwright-core')) || !fs.existsSync(path.join(webRoot, 'node_modules', 'three')))
    throw new Error(`${webRoot}/node_modules is missing playwright-core or three: run scripts/install-web.sh`);
  const bin = process.env.CLEAVE_BIN;
  if (!bin || !fs.existsSync(bin)) throw new Error(`CLEAVE_BIN='${bin}' is not the built cleave binary (run through ctest)`);
  return { chromium, bin };
}

export function screenshotDir() {
  const dir = process.env.CLEAVE_SCREENSHOTS || path.join(repoRoot, 'build', 'browser-screenshots');
  fs.mkdirSync(dir, { recursive: true });
  return dir;
}

export function freshSessionDir(name) {
  return fs.mkdtempSync(path.join(os.tmpdir(), `cleave-studio-${name}-`));
}

/// Starts `cleave studio` and resolves once it prints its URL. Returns {url, port, process, stop, kill}.
export async function startServer({ bin, session, model = 'abdomen', res = '63x21x42', port, extraArgs = [] }) {
  const args = ['studio', model, '--res', res, '--session', session, '--port', String(port ?? process.env.CLEAVE_STUDIO_PORT ?? 0),
    '--web-root', webRoot, ...extraArgs];
  if (model === null) args.splice(1, 3);
  const child = spawn(bin, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  const url = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`cleave studio did not start in 60 s:\n${output}`)), 60000);
    const onData = (chunk) => {
      output += chunk.toString();
      const m = output.match(/cleave studio: (http:\/\/[^\s]+)/);
      if (m) { clearTimeout(timer); resolve(m[1]); }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', (c) => { output += c.toString(); });
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`cleave studio exited with ${code}:\n${output}`)); });
  });
  child.removeAllListeners('exit');
  const exited = new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal })));
  return {
    url, port: Number(new URL(url).port), process: child, output: () => output, exited,
    async stop() { if (child.exitCode === null) child.kill('SIGTERM'); return exited; },
    async kill() { child.kill('SIGKILL'); return exited; },
  };
}

export async function launchBrowser(chromiumPath) {
  const require = createRequire(path.join(webRoot, 'package.json'));
  const { chromium } = require('playwright-core');
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'cleave-chromium-'));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width: 1280, height: 800 },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  return { context, async close() { await context.close(); fs.rmSync(userDataDir, { recursive: true, force: true }); } };
}

/// Opens the studio page and waits for the first result (the surface).
export async function openStudio(context, url) {
  const page = await context.newPage();
  const errors = [];
  const consoleErrors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  // Console errors of the page itself (WebGL, three.js); the browser's missing-favicon 404 is not one.
  page.on('console', (m) => { if (m.type() === 'error' && !/favicon/.test(m.location().url || '')) consoleErrors.push(m.text()); });
  await page.goto(url);
  await page.waitForFunction(() => window.studio && window.studio.app.result && window.studio.app.state, null, { timeout: 60000 });
  page.jsErrors = errors;
  page.consoleErrors = consoleErrors;
  return page;
}

export async function screenshot(page, name) {
  const file = path.join(screenshotDir(), `${name}.png`);
  await page.screenshot({ path: file });
  return file;
}

/// Waits until the page has a result computed for at least edit `seq`.
export async function waitForResult(page, seq, timeout = 60000) {
  await page.waitForFunction((s) => window.studio.app.result && window.studio.app.result.seq >= s, seq, { timeout });
  return page.evaluate(() => window.studio.app.result);
}

/// Canvas-relative pixels -> page pixels.
export async function canvasOrigin(page) {
  const box = await page.locator('#canvas').boundingBox();
  return [box.x, box.y, box.width, box.height];
}

/// A horizontal drag path across the surface near the canvas centre that hits the body at every point.
export async function surfacePath(page, lengthPx = 160, steps = 16) {
  const [, , w, h] = await canvasOrigin(page);
  for (const dy of [0, -60, 60, -120, 120]) {
    const pts = [];
    for (let i = 0; i <= steps; i++) pts.push([w / 2 - lengthPx / 2 + (i * lengthPx) / steps, h / 2 + dy]);
    const ok = await page.evaluate((p) => p.every(([x, y]) => window.studio.pickAt(x, y) !== null), pts);
    if (ok) return pts;
  }
  throw new Error('no horizontal path across the body near the canvas centre');
}

/// The fraction of surface vertices within `radius` mm of `centre` whose direction is within
/// 25 degrees of `tangent` (undirected), and how many there are.
export function alignedNear(result, centre, tangent, radius) {
  const p = result.surface.positions_mm, dir = result.fields.direction;
  const t = unit(tangent);
  let near = 0, aligned = 0;
  for (let i = 0; i < p.length / 3; i++) {
    if (Math.hypot(p[3 * i] - centre[0], p[3 * i + 1] - centre[1], p[3 * i + 2] - centre[2]) > radius) continue;
    near++;
    const v = unit([dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]]);
    if (Math.abs(v[0] * t[0] + v[1] * t[1] + v[2] * t[2]) > 0.9) aligned++;
  }
  return { near, fraction: near ? aligned / near : 0 };
}

export const unit = (v) => { const n = Math.hypot(...v); return v.map((x) => x / n); };

/// Canvas points (x, y) that all hit the body, or null.
export async function onBody(page, pts) {
  return (await page.evaluate((p) => p.every(([x, y]) => window.studio.pickAt(x, y) !== null), pts)) ? pts : null;
}

export async function mouseDrag(page, pts) {
  const [ox, oy] = await canvasOrigin(page);
  await page.mouse.move(ox + pts[0][0], oy + pts[0][1]);
  await page.mouse.down();
  for (const [x, y] of pts.slice(1)) await page.mouse.move(ox + x, oy + y, { steps: 2 });
  await page.mouse.up();
}
