// End-to-end tests of `cleave studio` in Debian's chromium (headless, playwright-core):
// the page against a real server on 127.0.0.1. Run by CTest (browser_e2e) with node --test.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { freshSessionDir, launchBrowser, mouseDrag, openStudio, requireTools, screenshot, startServer, surfacePath,
  waitForResult } from './harness.mjs';

const tools = requireTools();
// A coarse abdomen (about 2,500 cells of 6.7 mm) keeps the suite short on a loaded 2-core machine.
const RES = '48x16x32';
let browser;
before(async () => { browser = await launchBrowser(tools.chromium); });
after(async () => { await browser.close(); });

async function withStudio(name, fn, options = {}) {
  const session = options.session ?? freshSessionDir(name);
  const server = await startServer({ bin: tools.bin, session, res: RES, ...options });
  const page = await openStudio(browser.context, server.url);
  try {
    await fn({ page, server, session });
    assert.deepEqual(page.jsErrors, [], 'no JavaScript errors on the page');
  } finally {
    await screenshot(page, name).catch(() => {});
    await page.close();
    await server.stop();
  }
}

const unit = (v) => { const n = Math.hypot(...v); return v.map((x) => x / n); };

test('loads the built-in abdomen and shows its surface with a scale bar', async () => {
  await withStudio('01-load-abdomen', async ({ page }) => {
    const r = await page.evaluate(() => window.studio.app.result);
    const s = await page.evaluate(() => window.studio.app.state);
    assert.equal(s.model.source, 'abdomen');
    assert.deepEqual(s.model.resolution, [48, 16, 32]);
    assert.ok(r.cells > 1500 && r.cells < 48 * 16 * 32, `abdomen cells ${r.cells}`);
    assert.ok(r.surface.triangles.length >= 3 * 1000, 'a surface with triangles');
    assert.ok(r.surface.positions_mm.every(Number.isFinite), 'finite positions');
    assert.match(await page.locator('#scale-bar .label').textContent(), /^\d+ mm$/);
    assert.equal(await page.locator('#conn').textContent(), 'connected');
  });
});

test('a stroke drawn by mouse turns the direction field along it near the stroke', async () => {
  await withStudio('02-stroke-direction', async ({ page }) => {
    await page.click('button[data-tool=stroke]');
    const pts = await surfacePath(page);
    await mouseDrag(page, pts);
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    const seq = await page.evaluate(() => window.studio.app.state.seq);
    const r = await waitForResult(page, seq);
    // A stroke without control points still gives directions; the page says magnitudes are missing.
    assert.equal(r.design_error, undefined, r.design_error);
    assert.match(await page.locator('#notes').textContent(), /place a control point/);
    await page.click('button[data-tool=orbit]');
    await page.selectOption('#display', 'glyphs');
    await screenshot(page, '02-stroke-glyphs');
    await page.selectOption('#display', 'streamlines');
    assert.ok(r.streamlines_mm.length >= 10, `streamlines: ${r.streamlines_mm.length}`);
    const stroke = await page.evaluate(() => window.studio.app.state.design.strokes[0].points_mm);
    assert.ok(stroke.length >= 5, `stroke of ${stroke.length} points`);
    const dir = r.fields && r.fields.direction;
    assert.ok(dir, 'the result carries the direction field');
    // Every surface vertex within two cells of the stroke's middle: direction parallel to the stroke.
    const mid = Math.floor(stroke.length / 2);
    const tangent = unit(stroke[mid + 1].map((v, k) => v - stroke[mid - 1][k]));
    const p = r.surface.positions_mm;
    let near = 0, aligned = 0;
    for (let i = 0; i < p.length / 3; i++) {
      const d = Math.hypot(p[3 * i] - stroke[mid][0], p[3 * i + 1] - stroke[mid][1], p[3 * i + 2] - stroke[mid][2]);
      if (d > 2 * r.cell_size_mm) continue;
      near++;
      const v = unit([dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]]);
      if (Math.abs(v[0] * tangent[0] + v[1] * tangent[1] + v[2] * tangent[2]) > 0.9) aligned++;
    }
    assert.ok(near >= 3, `surface vertices near the stroke: ${near}`);
    assert.ok(aligned / near >= 0.8, `aligned ${aligned} of ${near}`);
  });
});

test('the magnitude tool places a control point and a typed value sets it', async () => {
  await withStudio('03-control-point', async ({ page }) => {
    await page.click('button[data-tool=magnitude]');
    const [x, y] = (await surfacePath(page))[8];
    const box = await page.locator('#canvas').boundingBox();
    await page.mouse.click(box.x + x, box.y + y);
    await page.waitForFunction(() => window.studio.app.state.design.control_points.length === 1);
    const p0 = await page.evaluate(() => window.studio.app.state.design.control_points[0]);
    assert.equal(p0.langer_kPa, 20);
    assert.equal(p0.cross_kPa, 10);
    await page.fill('#langer-kpa', '32.5');
    await page.press('#langer-kpa', 'Enter');
    await page.waitForFunction(() => window.studio.app.state.design.control_points[0].langer_kPa === 32.5);
    assert.equal(await page.evaluate(() => window.studio.app.state.design.control_points[0].cross_kPa), 10);
    await page.evaluate(() => document.activeElement.blur());
  });
});

test('the round-incision preview opens the incisions once stroke and magnitude are set', async () => {
  await withStudio('04a-incision-preview', async ({ page }) => {
    const r0Triangles = await page.evaluate(() => window.studio.app.result.surface.triangles.length);
    await page.click('button[data-tool=stroke]');
    const pts = await surfacePath(page);
    await mouseDrag(page, pts);
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    await page.click('button[data-tool=magnitude]');
    const box = await page.locator('#canvas').boundingBox();
    await page.mouse.click(box.x + pts[8][0], box.y + pts[8][1] + 10);
    await page.waitForFunction(() => window.studio.app.state.design.control_points.length === 1);
    // The designed tension stays near the control points (the equilibrium term of eq. 9 lets it
    // fall off away from them), so spread a few more over the visible skin.
    for (const [x, y] of [[pts[0][0], pts[0][1] - 50], [pts[16][0], pts[16][1] - 50], [pts[0][0], pts[0][1] + 50], [pts[16][0], pts[16][1] + 50]])
      await page.evaluate(([px, py]) => { const hit = window.studio.pickAt(px, py); return hit && window.studio.send('add_control_point', { position_mm: hit.point.toArray(), langer_kPa: 20, cross_kPa: 10 }); }, [x, y]);
    const seq = await page.evaluate(() => window.studio.app.state.seq);
    const r = await waitForResult(page, seq);
    assert.equal(r.design_error, undefined, r.design_error);
    assert.ok(r.incisions.length >= 5, `preview incisions measured: ${r.incisions.length}`);
    // The incisions are cut (holes in the surface, plugs hidden) and open when the designed stress
    // is released: with the demo's settings (w_E = 0, equilibrated, rim and inner surface held) the
    // skin is in tension everywhere, so every margin opens by a fraction of a millimetre to a few
    // (the demo at 3.6 mm cells: mean axis ratio 1.10) into an ellipse.
    const openings = r.incisions.map((i) => i.opening_mm.toFixed(2)).join(', ');
    assert.ok(r.incisions.every((i) => i.opening_mm > 0.1 && i.opening_mm < 5), `openings (mm): ${openings}`);
    const meanRatio = r.incisions.reduce((a, i) => a + i.axis_ratio, 0) / r.incisions.length;
    assert.ok(meanRatio > 1.02 && meanRatio < 1.3, `mean axis ratio ${meanRatio}`);
    assert.match(await page.locator('#preview-info').textContent(), /^opening \d+\.\d\d to \d+\.\d\d mm .*axis ratio 1\.\d{3}$/);
    assert.ok(r.surface.triangles.length < r0Triangles, 'the incision plugs are hidden from the surface');
    assert.ok(r.fields.displacement_mm.some((d) => d > 0.01), 'the surface is displaced');
    assert.ok(r.timings_ms.total > 0 && Number.isFinite(r.timings_ms.total));
    assert.match(await page.locator('#timings').textContent(), /total \d+ ms/);
    assert.match(await page.locator('#timing-table').textContent(), /computed \(server\)\d+ ms/);
    // The page's own clock: from sending its last edit to the frame that shows the result.
    await page.waitForFunction(() => window.studio.app.pictureMs.length > 0);
    const table = await page.locator('#timing-table').textContent();
    assert.match(table, /received and decoded \(page\)\d+ ms/);
    assert.match(table, /edit to picture \(page\)\d+ ms/);
    const pictureMs = await page.evaluate(() => window.studio.app.pictureMs.at(-1));
    assert.ok(pictureMs > r.timings_ms.total, `edit to picture ${pictureMs} ms includes the server's ${r.timings_ms.total} ms`);
    await page.click('button[data-tool=orbit]');
    // Eigenvalue map with its legend in kPa; the equilibrium residual; the incisions' cut faces.
    await page.selectOption('#display', 'langer');
    assert.match(await page.locator('#legend .title').textContent(), /Eigenvalue along Langer \(kPa\)/);
    // Five control points of 20 kPa with w_E = 0 (the demo's settings): 20 kPa all over, or a range.
    const title = await page.locator('#legend .title').textContent();
    assert.ok(Number(await page.locator('#legend .hi').textContent()) > Number(await page.locator('#legend .lo').textContent()) ||
      /uniform 20\.00/.test(title), title);
    await screenshot(page, '04a-eigenvalue-langer');
    await page.selectOption('#display', 'residual');
    assert.match(await page.locator('#legend .title').textContent(), /Equilibrium residual .*\(kPa\)/);
    await screenshot(page, '04a-residual');
    assert.ok(r.fields.traction_kPa.some((v) => v > 0), 'released traction on the incision faces');
    assert.ok(r.fields.cut_depth.some((v) => v >= 0 && v <= 1), 'cut faces coloured by depth');
    await page.selectOption('#display', 'traction');
    assert.match(await page.locator('#legend .title').textContent(), /released traction \(kPa\)/);
    await screenshot(page, '04a-traction');
    await page.selectOption('#display', 'depth');
  });
});

test('a scalpel cut drawn by mouse opens and its wound width is reported in mm', async () => {
  await withStudio('04b-cut-wound', async ({ page }) => {
    const pts = await surfacePath(page, 200, 20);
    await page.evaluate((p) => {
      const a = p.map(([x, y]) => window.studio.pickAt(x, y).point.toArray());
      return window.studio.send('add_stroke', { points_mm: a });
    }, pts.map(([x, y]) => [x, y - 40]));
    await page.evaluate((p) => window.studio.send('add_control_point', { position_mm: window.studio.pickAt(p[0], p[1]).point.toArray(), langer_kPa: 20, cross_kPa: 10 }), pts[10]);
    await page.click('button[data-tool=cut]');
    await page.fill('#cut-depth', '10');  // 1.5 cells of the coarse test model
    // Across the stroke direction: a vertical cut through the middle.
    const [x0, y0] = pts[10];
    const vertical = Array.from({ length: 13 }, (_, i) => [x0, y0 - 60 + 10 * i]);
    await mouseDrag(page, vertical);
    await page.waitForFunction(() => window.studio.app.state.design.cuts.length === 1);
    const seq = await page.evaluate(() => window.studio.app.state.seq);
    const r = await waitForResult(page, seq);
    assert.equal(r.cut_error, undefined, r.cut_error);
    // The opening was streamed frame by frame over the WebSocket before the result.
    const frames = await page.evaluate(() => ({ count: window.studio.app.frames, last: window.studio.app.lastFrame }));
    assert.ok(frames.count >= 5, `frames streamed: ${frames.count}`);
    assert.ok(frames.last.time_s > 0 && Number.isFinite(frames.last.width_mm), `last frame ${JSON.stringify(frames.last)}`);
    assert.ok(r.timings_ms.frame > 0, 'the page gets the time of one simulation frame');
    assert.equal(r.wounds.length, 1);
    assert.ok(r.wounds[0].width_mm > 0.05 && r.wounds[0].width_mm < 100, `wound width ${r.wounds[0].width_mm} mm`);
    assert.match(await page.locator('#wound-width').textContent(), /^\d+\.\d mm/);
    await page.click('button[data-tool=orbit]');
    await page.selectOption('#display', 'displacement');
    await screenshot(page, '04b-cut-open');
    await page.click('#reset-cuts');
    await page.waitForFunction(() => window.studio.app.state.design.cuts.length === 0);
    const r2 = await waitForResult(page, seq + 1);
    assert.equal(r2.wounds.length, 0, 'reset restores the uncut body');
  });
});

test('undo and redo restore the design step by step', async () => {
  await withStudio('04-undo-redo', async ({ page }) => {
    await page.click('button[data-tool=stroke]');
    const pts = await surfacePath(page);
    await mouseDrag(page, pts);
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    await mouseDrag(page, pts.map(([x, y]) => [x, y + 20]));
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 2);
    await page.click('#undo');
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    await page.click('#undo');
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 0);
    assert.equal(await page.locator('#undo').isDisabled(), true);
    await page.click('#redo');
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    const s = await page.evaluate(() => window.studio.app.state);
    assert.equal(s.can_redo, true);
    assert.equal(s.seq, 5, 'two strokes, two undos and a redo: five acknowledged edits');
  });
});

test('save, reload the page, load: the same design comes back', async () => {
  await withStudio('05-save-load', async ({ page }) => {
    await page.click('button[data-tool=stroke]');
    await mouseDrag(page, await surfacePath(page));
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    await page.evaluate(() => window.studio.send('add_control_point', { position_mm: window.studio.app.state.design.strokes[0].points_mm[3], langer_kPa: 18, cross_kPa: 7 }));
    const saved = await page.evaluate(() => window.studio.app.state.design);
    await page.fill('#file-name', 'my-design.json');
    await page.click('#save');
    await page.waitForSelector('#files-note a');
    await page.evaluate(() => window.studio.send('reset_cuts'));
    await page.evaluate(() => window.studio.send('delete_stroke', { id: window.studio.app.state.design.strokes[0].id }));
    await page.reload();
    await page.waitForFunction(() => window.studio && window.studio.app.state && window.studio.app.result);
    assert.equal(await page.evaluate(() => window.studio.app.state.design.strokes.length), 0);
    await page.fill('#file-name', 'my-design.json');
    await page.click('#load');
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    const loaded = await page.evaluate(() => window.studio.app.state.design);
    assert.deepEqual(loaded.strokes.map((s) => s.points_mm), saved.strokes.map((s) => s.points_mm));
    assert.deepEqual(loaded.control_points.map(({ position_mm, langer_kPa, cross_kPa }) => ({ position_mm, langer_kPa, cross_kPa })),
      saved.control_points.map(({ position_mm, langer_kPa, cross_kPa }) => ({ position_mm, langer_kPa, cross_kPa })));
    // The saved case is the CLI's format, served from the session folder.
    const text = await page.evaluate(() => fetch('/session/my-design.json').then((r) => r.text()));
    const doc = JSON.parse(text);
    assert.equal(doc.model.source, 'abdomen');
    assert.equal(doc.design.strokes.length, 1);
    assert.ok(Array.isArray(doc.design.strokes[0].points), "case_design format: strokes[].points");
  });
});

test('killing the server (SIGKILL) mid-session loses no acknowledged edit', async () => {
  const session = freshSessionDir('kill');
  let acknowledged;
  {
    const server = await startServer({ bin: tools.bin, session, res: RES });
    const page = await openStudio(browser.context, server.url);
    await page.click('button[data-tool=stroke]');
    await mouseDrag(page, await surfacePath(page));
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    // A burst of edits; the kill lands while some are in flight. Count only the acknowledged ones.
    acknowledged = await page.evaluate(async () => {
      const acks = [];
      const p = window.studio.app.state.design.strokes[0].points_mm[2];
      for (let i = 0; i < 12; i++) {
        const r = await window.studio.connection.request('add_control_point', { position_mm: p, langer_kPa: 10 + i, cross_kPa: 5 });
        acks.push(r.seq);
      }
      return { seq: acks[acks.length - 1], design: window.studio.app.state.design };
    });
    page.evaluate(() => { for (let i = 0; i < 20; i++) window.studio.connection.request('add_control_point', { position_mm: window.studio.app.state.design.control_points[0].position_mm, langer_kPa: 50 + i }).catch(() => {}); });
    await server.kill();
    await screenshot(page, '06-before-kill');
    await page.close();
  }
  const restarted = await startServer({ bin: tools.bin, session, model: null });
  try {
    const page = await openStudio(browser.context, restarted.url);
    const state = await page.evaluate(() => window.studio.app.state);
    assert.ok(state.seq >= acknowledged.seq, `restored seq ${state.seq} >= acknowledged ${acknowledged.seq}`);
    for (const p of acknowledged.design.control_points)
      assert.ok(state.design.control_points.some((q) => q.id === p.id && q.langer_kPa === p.langer_kPa), `control point ${p.id} kept`);
    assert.deepEqual(state.design.strokes, acknowledged.design.strokes);
    assert.match(restarted.output(), /edits restored/);
    await screenshot(page, '06-after-restart');
    await page.close();
  } finally {
    await restarted.stop();
  }
});

test('two pages on one session see each other\'s edits', async () => {
  await withStudio('07-two-clients', async ({ page, server }) => {
    const other = await openStudio(browser.context, server.url);
    await page.click('button[data-tool=stroke]');
    await mouseDrag(page, await surfacePath(page));
    await other.waitForFunction(() => window.studio.app.state.design.strokes.length === 1);
    await other.evaluate(() => window.studio.send('undo'));
    await page.waitForFunction(() => window.studio.app.state.design.strokes.length === 0);
    await other.close();
  });
});
