#!/usr/bin/env node
// The studio's edit-to-result time as a client sees it, over the WebSocket of a running server:
//
//   build/release/bin/cleave studio abdomen --res 126x41x84 --session /tmp/s --port 8765 &
//   node --experimental-websocket scripts/studio-timings.mjs ws://127.0.0.1:8765/ws [DRAGS] [SETTLE_S] [CUT_DEPTH_MM]
//
// On a bare session it designs what `cleave demo` designs on the abdomen (three strokes along x
// over the skin at 20, 50 and 80 % of its length, four control points of 20 / 10 kPa), then moves
// the first stroke one cell along z per edit (fresh cells each time, as a dragged stroke; the
// offset's y follows the skin's height under the stroke's middle) and
// waits for each edit's result. It prints, per edit, the time from sending the edit to its result
// arriving (received and decoded, before any drawing), the server's own stage times, and, when
// the picture came from a provisional stress, when its design_final arrived; then the medians.
// SETTLE_S (default 30) seconds pass between the design and the first drag: the incision
// preview's factorization runs in the background for 15-30 s at 45k cells after the design, and
// until it is ready the preview is solved by the multigrid (200-350 ms). The drags follow the
// skin for about 12 cells; start each run on a fresh session.
// CUT_DEPTH_MM (optional, > 0): after the drags, a scalpel cut of that depth across the middle of
// the skin (along x, from 35 to 65 % of the width): it prints each streamed frame's arrival after
// the one before it, the server's mean step time and the wound width, then the cut's result.
import { decodeMessage } from '../web/js/packed.js';

const url = process.argv[2];
const drags = Number(process.argv[3] ?? 8);
const settleS = Number(process.argv[4] ?? 30);
const cutDepthMm = process.argv[5] === undefined ? 0 : Number(process.argv[5]);
if (!url || !(drags > 0) || !(settleS >= 0) || !(cutDepthMm >= 0)) {
  console.error('usage: studio-timings.mjs ws://127.0.0.1:PORT/ws [DRAGS] [SETTLE_S] [CUT_DEPTH_MM]');
  process.exit(2);
}

const ws = new WebSocket(url);
ws.binaryType = 'arraybuffer';
let nextReq = 1;
const replies = new Map();
const waiters = [];
let latestResult = null;
const arrivals = [];  // every message with its arrival time

ws.onmessage = (event) => {
  const m = decodeMessage(event.data);
  const at = performance.now();
  arrivals.push({ m, at });
  if (m.type === 'result') latestResult = m;
  if (m.req !== undefined && replies.has(m.req)) {
    replies.get(m.req)(m);
    replies.delete(m.req);
  }
  for (const w of [...waiters]) if (w.test(m)) { waiters.splice(waiters.indexOf(w), 1); w.resolve({ m, at }); }
};

function request(cmd, fields = {}) {
  const req = nextReq++;
  return new Promise((resolve) => {
    replies.set(req, resolve);
    ws.send(JSON.stringify({ ...fields, cmd, req }));
  });
}

function waitFor(test, timeoutMs = 600000) {
  return new Promise((resolve, reject) => {
    const w = { test, resolve };
    waiters.push(w);
    // unref: a pending timeout does not keep the script alive once the socket is closed.
    setTimeout(() => { const i = waiters.indexOf(w); if (i >= 0) { waiters.splice(i, 1); reject(new Error('timed out')); } }, timeoutMs).unref();
  });
}

const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s.length ? s[Math.floor((s.length - 1) / 2)] : NaN; };

/// The highest surface vertex within one cell of (x, z): a point on the skin.
function skinPoint(result, x, z) {
  const p = result.surface.positions_mm;
  const h = result.cell_size_mm;
  let best = null;
  for (let i = 0; i < p.length; i += 3) {
    if (Math.abs(p[i] - x) > h || Math.abs(p[i + 2] - z) > h) continue;
    if (!best || p[i + 1] > best[1]) best = [p[i], p[i + 1], p[i + 2]];
  }
  if (!best) throw new Error(`no surface vertex near x = ${x}, z = ${z}`);
  return best;
}

await new Promise((resolve, reject) => { ws.onopen = resolve; ws.onerror = reject; });
const hello = await request('hello');
let state = hello.type === 'state' ? hello : await waitFor((m) => m.type === 'state').then((r) => r.m);
if (!latestResult) await waitFor((m) => m.type === 'result');
const [lo, hi] = latestResult.bounding_box_mm;
const w = hi[0] - lo[0], l = hi[2] - lo[2];
const h = latestResult.cell_size_mm;

if (state.design.strokes.length === 0) {
  for (const f of [0.2, 0.5, 0.8]) {
    const points = [];
    for (let i = 1; i <= 9; i++) points.push(skinPoint(latestResult, lo[0] + 0.1 * i * w, lo[2] + f * l));
    await request('add_stroke', { points_mm: points });
  }
  let ack;
  for (const fx of [0.3, 0.7]) for (const fz of [0.3, 0.7])
    ack = await request('add_control_point', { position_mm: skinPoint(latestResult, lo[0] + fx * w, lo[2] + fz * l), langer_kPa: 20, cross_kPa: 10 });
  const started = performance.now();
  await waitFor((m) => m.type === 'result' && m.seq >= ack.seq);
  console.log(`design: ${(performance.now() - started).toFixed(0)} ms to its first result (${latestResult.cells} cells)`);
  state = await request('get_state');
  console.log(`waiting ${settleS} s for the preview's factorization`);
  await new Promise((resolve) => setTimeout(resolve, 1000 * settleS));
}
const stroke = state.design.strokes[0].id;
let middle = state.design.strokes[0].points_mm[Math.floor(state.design.strokes[0].points_mm.length / 2)];

const rows = [];
for (let k = 0; k < drags; k++) {
  const sent = performance.now();
  const next = skinPoint(latestResult, middle[0], middle[2] + h);
  const ack = await request('move_stroke', { id: stroke, offset_mm: [0, next[1] - middle[1], h] });
  const ackMs = performance.now() - sent;
  middle = [middle[0], next[1], middle[2] + h];
  const { m: result, at } = await waitFor((m) => m.type === 'result' && m.seq >= ack.seq);
  const row = { edit_ms: at - sent, ack_ms: ackMs, server: result.timings_ms, provisional: !!(result.equilibrium_residual || {}).provisional };
  if (row.provisional) {
    const { at: finalAt } = await waitFor((m) => (m.type === 'design_final' || m.type === 'error') && m.seq === result.seq);
    row.final_ms = finalAt - sent;
  }
  rows.push(row);
  const t = row.server;
  console.log(`drag ${k + 1}: ack after ${row.ack_ms.toFixed(0)} ms, result after ${row.edit_ms.toFixed(0)} ms (server ${t.total.toFixed(0)}: directions ${(t.directions ?? 0).toFixed(0)}, ` +
    `equilibration ${(t.equilibration ?? 0).toFixed(0)}, incisions ${(t.incisions ?? 0).toFixed(0)}, surface ${(t.surface ?? 0).toFixed(0)})` +
    (row.provisional ? `, provisional; final after ${row.final_ms.toFixed(0)} ms` : '') +
    (result.design_error ? ` design error: ${result.design_error}` : ''));
}
console.log(`median over ${rows.length} drags: ack ${median(rows.map((r) => r.ack_ms)).toFixed(0)} ms, result ${median(rows.map((r) => r.edit_ms)).toFixed(0)} ms, server total ` +
  `${median(rows.map((r) => r.server.total)).toFixed(0)} ms, provisional ${rows.filter((r) => r.provisional).length}`);

if (cutDepthMm > 0) {
  const path = [];
  for (let i = 0; i <= 6; i++) path.push(skinPoint(latestResult, lo[0] + (0.35 + 0.05 * i) * w, lo[2] + 0.5 * l));
  const sent = performance.now();
  const ack = await request('add_cut', { kind: 'scalpel', depth_mm: cutDepthMm, path_mm: path });
  const frames = [];
  let last = sent;
  const { m: result, at } = await new Promise((resolve, reject) => {
    waiters.push({ test: (m) => {
      if (m.type === 'frame') {
        const now = performance.now();
        frames.push({ index: m.index, after_ms: now - last, step_ms: m.step_ms, width_mm: m.width_mm });
        last = now;
      }
      return m.type === 'result' && m.seq >= ack.seq;
    }, resolve });
    setTimeout(() => reject(new Error('the cut timed out')), 600000).unref();
  });
  for (const f of frames)
    console.log(`frame ${f.index}: ${f.after_ms.toFixed(0)} ms after the ${f.index ? 'frame before' : 'cut was sent'}, ` +
      `mean step ${f.step_ms.toFixed(0)} ms, width ${(f.width_mm ?? NaN).toFixed(2)} mm`);
  const later = frames.filter((f) => f.index > 1).map((f) => f.after_ms);
  const t = result.timings_ms;
  console.log(`cut: result after ${(at - sent).toFixed(0)} ms (server ${t.total.toFixed(0)}: opening ${(t.opening ?? 0).toFixed(0)}, ` +
    `frame ${(t.frame ?? 0).toFixed(0)}, incisions ${(t.incisions ?? 0).toFixed(0)}); frames after the first step: median ` +
    `${median(later).toFixed(0)} ms apart${result.cut_error ? `; cut error: ${result.cut_error}` : ''}`);
}
ws.close();
