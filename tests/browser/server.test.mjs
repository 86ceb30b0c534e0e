// Server safety tests of `cleave studio` without a browser: loopback binding, a second server on
// the same port, path traversal over HTTP, malformed and oversized WebSocket messages, a bounded
// soak (16 concurrent clients editing for CLEAVE_SOAK_SECONDS on 127.0.0.1: no error, every
// acknowledged edit in the state and in the journal after a restart, resident memory flat), and
// SIGKILL during a scripted edit stream, repeated CLEAVE_KILL_ROUNDS times: every acknowledged
// edit survives and the session always reopens.
// Environment: CLEAVE_SOAK_SECONDS (default 20: CI; docs/ROBUSTNESS.md records a 60 s run),
// CLEAVE_KILL_ROUNDS (default 6).
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import net from 'node:net';
import { decodeMessage } from '../../web/js/packed.js';
import { freshSessionDir, requireTools, startServer } from './harness.mjs';

const SOAK_SECONDS = Number(process.env.CLEAVE_SOAK_SECONDS || 20);  // bounded soak; 60 s in docs/ROBUSTNESS.md
const KILL_ROUNDS = Number(process.env.CLEAVE_KILL_ROUNDS || 6);
// Resident memory is sampled once the first edit's result is in (the caches it builds are the
// bulk); it may still grow in the first quarter of the soak, after that the median of the last
// quarter must stay within this of the median of the second quarter.
const SOAK_RSS_GROWTH_MIB = 32;
const SOAK_CLIENTS = 16;
const tools = requireTools();
let server;
before(async () => { server = await startServer({ bin: tools.bin, session: freshSessionDir('server') }); });
after(async () => { await server.stop(); });

function rawGet(port, rawPath) {
  return new Promise((resolve, reject) => {
    const req = http.request({ host: '127.0.0.1', port, path: rawPath, method: 'GET' }, (res) => {
      let body = '';
      res.on('data', (c) => { body += c; });
      res.on('end', () => resolve({ status: res.statusCode, body }));
    });
    req.on('error', reject);
    req.end();
  });
}

function openSocket(url) {
  return new Promise((resolve, reject) => {
    const ws = new WebSocket(url.replace('http', 'ws') + 'ws');
    ws.binaryType = 'arraybuffer';  // results and frames are binary messages (web/js/packed.js)
    const replies = new Map();
    ws.pending = replies;
    ws.onmessage = (e) => {
      const m = decodeMessage(e.data);
      if (m.req !== undefined && replies.has(m.req)) { replies.get(m.req).resolve(m); replies.delete(m.req); }
      if (ws.onpush) ws.onpush(m);
    };
    // A connection that drops (the server was killed) rejects the requests still waiting.
    ws.onclose = () => { for (const p of replies.values()) p.reject(new Error('connection closed')); replies.clear(); };
    ws.onopen = () => resolve(ws);
    ws.onerror = reject;
  });
}
let nextReq = 1;
function request(ws, message) {
  const req = nextReq++;
  return new Promise((resolve, reject) => {
    if (ws.readyState !== WebSocket.OPEN) { reject(new Error('connection closed')); return; }
    ws.pending.set(req, { resolve, reject });
    ws.send(JSON.stringify({ ...message, req }));
  });
}

/// Resident set size of a process in MiB (Linux /proc), or NaN once it has exited.
function rssMiB(pid) {
  try {
    const m = fs.readFileSync(`/proc/${pid}/status`, 'utf8').match(/VmRSS:\s+(\d+) kB/);
    return m ? Number(m[1]) / 1024 : NaN;
  } catch { return NaN; }
}
function median(values) {
  const v = [...values].sort((a, b) => a - b);
  return v[Math.floor(v.length / 2)];
}

test('binds to 127.0.0.1 by default and prints the URL', () => {
  assert.match(server.url, /^http:\/\/127\.0\.0\.1:\d+\/$/);
});

test('a second server on the same port fails with a clear error', () => {
  const r = spawnSync(tools.bin, ['studio', '--session', freshSessionDir('second'), '--port', String(server.port)], { encoding: 'utf8', timeout: 60000 });
  assert.equal(r.status, 2);
  assert.match(r.stderr, new RegExp(`port ${server.port} is already in use on 127\\.0\\.0\\.1`));
});

test('static serving and downloads never leave the web root or the session folder', async () => {
  assert.equal((await rawGet(server.port, '/')).status, 200);
  assert.equal((await rawGet(server.port, '/vendor/three.module.js')).status, 200);
  for (const p of ['/../../../../etc/passwd', '/%2e%2e/%2e%2e/etc/passwd', '/js/../../README.md', '/session/../../etc/passwd',
    '/session/%2e%2e%2fsession.json', '/%00', '/node_modules/three/package.json', '/session/journal.jsonl', '//etc/passwd']) {
    const r = await rawGet(server.port, p);
    assert.ok(r.status === 403 || r.status === 404 || r.status === 400, `${p} -> ${r.status}`);
    assert.ok(!r.body.includes('root:'), `${p} leaked a file`);
  }
});

test('malformed, oversized and unknown messages get an error reply and the session stays intact', async () => {
  const ws = await openSocket(server.url);
  const before = await request(ws, { cmd: 'get_state' });
  const cases = [
    [{ cmd: 'fly' }, /unknown command 'fly'/],
    [{ cmd: 'add_stroke', points_mm: [[0, 0, 0]] }, /points_mm .*expected an array of 2 to 4096 points/],
    [{ cmd: 'add_stroke', points_mm: [[0, 0, 0], [1, 'x', 2]] }, /points_mm\/1/],
    [{ cmd: 'delete_stroke', id: 12345 }, /no stroke with id 12345/],
    [{ cmd: 'set_control_point', id: 1, langer_kPa: 1e9 }, /no control point with id 1|langer_kPa/],
    [{ cmd: 'save', file: '../escape.json' }, /outside the session folder/],
    [{ cmd: 'load', file: '/etc/passwd' }, /outside the session folder/],
    [{ cmd: 'export', format: 'vtu', file: '../../x.vtu' }, /outside the session folder/],
    [{ cmd: 'undo' }, /nothing to undo/],
    // 40 three-byte characters: the name is quoted up to 80 bytes without cutting a character
    // (a cut one made the reply invalid UTF-8 and its dump threw out of the read handler).
    [{ cmd: '\u20ac'.repeat(40) }, /unknown command '\u20ac{26}'/],
    [{ cmd: 'save', file: '\u20ac'.repeat(100) + '.json' }, /outside the session folder|\u20ac/],
  ];
  for (const [message, expected] of cases) {
    const r = await request(ws, message);
    assert.equal(r.type, 'error', JSON.stringify(message));
    assert.match(r.message, expected);
  }
  const errors = [];
  ws.onpush = (m) => { if (m.type === 'error' && m.req === undefined) errors.push(m.message); };
  ws.send('{not json');
  ws.send(JSON.stringify({ cmd: 'add_stroke', points_mm: 'x'.repeat(3 << 20) }));
  await new Promise((resolve) => setTimeout(resolve, 500));
  assert.ok(errors.some((e) => /invalid JSON/.test(e)), errors.join('\n'));
  const afterState = await request(ws, { cmd: 'get_state' });
  assert.equal(afterState.seq, before.seq);
  assert.deepEqual(afterState.design, before.design);
  // A message over the 4 MiB limit closes that connection only; the server keeps serving.
  const big = await openSocket(server.url);
  const closed = new Promise((resolve) => { big.onclose = resolve; });
  big.send('x'.repeat((4 << 20) + 16));
  await closed;
  assert.equal((await request(ws, { cmd: 'ping' })).type, 'pong');
  ws.close();
});

/// A WebSocket client that says hello and then stops reading: a raw TCP socket, paused.
function openStalledClient(port) {
  return new Promise((resolve, reject) => {
    const socket = net.connect(port, '127.0.0.1');
    socket.on('error', reject);
    socket.once('connect', () => {
      socket.write(`GET /ws HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
                   'Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n');
      socket.once('data', (reply) => {
        if (!/^HTTP\/1\.1 101/.test(reply.toString())) { reject(new Error(`no upgrade: ${reply}`)); return; }
        const payload = Buffer.from(JSON.stringify({ cmd: 'hello' }));
        const mask = Buffer.from([1, 2, 3, 4]);
        const frame = Buffer.concat([Buffer.from([0x81, 0x80 | payload.length]), mask,
          Buffer.from(payload.map((b, i) => b ^ mask[i % 4]))]);
        socket.write(frame);
        socket.pause();  // never read again
        resolve(socket);
      });
    });
  });
}

// A client that stops reading must not make the server hold every result since (2.5 MB each at
// 45k cells): it holds the one being written and the newest (a newer result replaces an unsent
// one), and once its unsent messages pass the byte budget (--max-send-queue-mb; here 0.5 MB,
// below two results of this size, above one) it is disconnected; the client that reads gets
// every result and the server goes on.
test('a client that stops reading is dropped at the send-queue byte budget; the others go on', { timeout: 180000 }, async () => {
  const slow = await startServer({ bin: tools.bin, session: freshSessionDir('slow'), res: '48x16x32',
    extraArgs: ['--max-send-queue-mb', '0.5'] });
  try {
    const stalled = await openStalledClient(slow.port);
    let stalledClosed = false;
    stalled.on('close', () => { stalledClosed = true; });
    const ws = await openSocket(slow.url);
    let results = 0;
    let resultBytes = 0;
    let waitResult = null;
    ws.binaryType = 'arraybuffer';
    ws.onpush = (m) => { if (m.type === 'result') { results++; if (waitResult) waitResult(); } };
    const rawHandler = ws.onmessage;
    ws.onmessage = (e) => { if (typeof e.data !== 'string') resultBytes = Math.max(resultBytes, e.data.byteLength); rawHandler(e); };
    assert.equal((await request(ws, { cmd: 'add_control_point', position_mm: [0, 0, 0], langer_kPa: 20, cross_kPa: 10 })).type, 'ack');
    const state = await request(ws, { cmd: 'get_state' });
    const id = state.design.control_points[0].id;
    // Edits until the stalled client's queue has passed the budget beyond what the kernel buffers
    // (a few MB on loopback), at most 200.
    let edits = 0;
    for (; edits < 200; edits++) {
      const arrived = new Promise((resolve) => { waitResult = resolve; });
      const ack = await request(ws, { cmd: 'set_control_point', id, langer_kPa: 21 + (edits % 40) });
      assert.equal(ack.type, 'ack', JSON.stringify(ack));
      await arrived;
      if (edits >= 8 && edits * resultBytes > (24 << 20)) break;
    }
    // Once resumed, the stalled client reads what the kernel held and then the server's close.
    stalled.resume();
    stalled.on('data', () => {});
    const deadline = Date.now() + 20000;
    while (!stalledClosed && Date.now() < deadline) await new Promise((r) => setTimeout(r, 100));
    assert.ok(stalledClosed, `the stalled client was not dropped after ${edits} edits of ${resultBytes} bytes each`);
    assert.ok(results >= edits, `the reading client got ${results} results for ${edits} edits`);
    assert.ok(resultBytes > (1 << 19) / 2 && resultBytes < (1 << 19), `results of ${resultBytes} bytes: one fits the budget, two do not`);
    assert.equal((await request(ws, { cmd: 'ping' })).type, 'pong');
    ws.close();
  } finally {
    await slow.stop();
  }
});

// A client that reads slowly while another one edits in a burst: the broadcast states and results
// it has not been sent yet are replaced by the newest (only the newest design matters), so 600 edits, more
// than the 512 queued messages that drop a client, leave it connected; once it reads, it gets far
// fewer states than edits, the last one the newest. Results first fill what the kernel buffers
// for it (a few MB on loopback), so that the server's own queue holds the states.
test('a slow reader gets the newest state instead of one per edit', { timeout: 180000 }, async () => {
  const server = await startServer({ bin: tools.bin, session: freshSessionDir('coalesce'), res: '48x16x32' });
  try {
    const stalled = await openStalledClient(server.port);
    let stalledClosed = false;
    stalled.on('close', () => { stalledClosed = true; });
    const ws = await openSocket(server.url);
    assert.equal((await request(ws, { cmd: 'add_control_point', position_mm: [0, 0, 0], langer_kPa: 20, cross_kPa: 10 })).type, 'ack');
    const id = (await request(ws, { cmd: 'get_state' })).design.control_points[0].id;
    let resultBytes = 0;
    let waitResult = null;
    ws.onpush = (m) => { if (m.type === 'result' && waitResult) waitResult(); };
    const rawHandler = ws.onmessage;
    ws.onmessage = (e) => { if (typeof e.data !== 'string') resultBytes = Math.max(resultBytes, e.data.byteLength); rawHandler(e); };
    let filling = 0;
    let before = 0;
    for (; filling < 200 && !(filling >= 8 && filling * resultBytes > (24 << 20)); filling++) {
      const arrived = new Promise((resolve) => { waitResult = resolve; });
      before = (await request(ws, { cmd: 'set_control_point', id, langer_kPa: 30 + (filling % 40) })).seq;
      await arrived;
    }
    const EDITS = 600;
    let last = 0;
    for (let e = 0; e < EDITS; e++) {
      const ack = await request(ws, { cmd: 'set_control_point', id, langer_kPa: 21 + (e % 40) });
      assert.equal(ack.type, 'ack', JSON.stringify(ack));
      last = ack.seq;
    }
    assert.equal((await request(ws, { cmd: 'ping' })).type, 'pong');
    ws.close();
    // Read what was queued for the stalled client until it stays quiet for a second.
    const chunks = [];
    stalled.on('data', (c) => chunks.push(c));
    stalled.resume();
    let size = -1;
    while (size !== chunks.length) { size = chunks.length; await new Promise((r) => setTimeout(r, 1000)); }
    assert.ok(!stalledClosed, 'the slow reader was dropped');
    const text = Buffer.concat(chunks).toString('latin1');
    const states = [...text.matchAll(/"type":"state"/g)].length;
    const seqs = [...text.matchAll(/"seq":(\d+),"type":"state"|"type":"state"[^}]*?"seq":(\d+)/g)].map((m) => Number(m[1] ?? m[2]));
    const burst = seqs.filter((s) => s > before).length;
    assert.ok(states < (filling + EDITS) / 4, `${states} states for ${filling + EDITS} edits`);
    assert.ok(burst < EDITS / 4, `${burst} states for the burst's ${EDITS} edits`);
    assert.ok(seqs.includes(last), `the newest state (seq ${last}) among ${seqs.slice(-5)}`);
    // Results too: each is a snapshot, so a newer one takes the place of one still unsent.
    const results = [...text.matchAll(/"type":"result"/g)].length;
    assert.ok(results < (filling + EDITS) / 4, `${results} results for ${filling + EDITS} edits`);
    stalled.destroy();
  } finally {
    await server.stop();
  }
});

test(`soak: ${SOAK_CLIENTS} clients editing for ${SOAK_SECONDS} s lose no acknowledged edit`, { timeout: (SOAK_SECONDS + 90) * 1000 }, async () => {
  const session = freshSessionDir('soak');
  const soak = await startServer({ bin: tools.bin, session });
  const acked = [];
  let errors = 0;
  let clients = [];
  let sampler = null;
  try {
    clients = await Promise.all(Array.from({ length: SOAK_CLIENTS }, () => openSocket(soak.url)));
    // Warm-up: the first edit's result builds what every later one reuses (the incision preview's
    // factor: about 200 MiB at this size), so memory is sampled from its arrival on.
    let warmSeq = Infinity;  // the warm-up edit's seq once acknowledged (its result follows the ack)
    const firstResult = new Promise((resolve) => {
      clients[0].onpush = (m) => { if (m.type === 'result' && m.seq >= warmSeq) resolve(); };
    });
    const warmup = await request(clients[0], { cmd: 'add_control_point', position_mm: [-1, 0, 0], langer_kPa: 10, cross_kPa: 1 });
    assert.equal(warmup.type, 'ack');
    warmSeq = warmup.seq;
    acked.push(warmup.seq);
    await firstResult;
    clients[0].onpush = null;
    const rss = [];
    sampler = setInterval(() => rss.push(rssMiB(soak.process.pid)), 500);
    const deadline = Date.now() + SOAK_SECONDS * 1000;
    await Promise.all(clients.map(async (ws, c) => {
      let i = 0;
      while (Date.now() < deadline) {
        const add = await request(ws, { cmd: 'add_control_point', position_mm: [c, i, 0], langer_kPa: 1 + (i % 50), cross_kPa: 1 });
        if (add.type !== 'ack') { errors++; continue; }
        acked.push(add.seq);
        // Keep the design bounded (memory must stay flat): delete what this client added, by its
        // position, except every 16th point.
        const state = await request(ws, { cmd: 'get_state' });
        const mine = state.design.control_points.find((p) => p.position_mm[0] === c && p.position_mm[1] === i);
        if (mine && i % 16 !== 0) {
          const del = await request(ws, { cmd: 'delete_control_point', id: mine.id });
          if (del.type === 'ack') acked.push(del.seq); else errors++;
        }
        i++;
      }
    }));
    clearInterval(sampler);
    const final = await request(clients[0], { cmd: 'get_state' });
    for (const ws of clients) ws.close();
    assert.equal(errors, 0);
    const quarter = Math.floor(rss.length / 4);
    const warm = median(rss.slice(quarter, 2 * quarter));
    const last = median(rss.slice(3 * quarter));
    assert.ok(last - warm < SOAK_RSS_GROWTH_MIB, `resident memory grew from ${warm.toFixed(1)} to ${last.toFixed(1)} MiB`);
    assert.ok(acked.length > SOAK_CLIENTS * 10, `acknowledged edits: ${acked.length}`);
    assert.equal(new Set(acked).size, acked.length, 'every acknowledged seq is unique');
    assert.equal(final.seq, Math.max(...acked), 'the state holds every acknowledged edit');
    await soak.kill();
    const again = await startServer({ bin: tools.bin, session, model: null });
    const ws = await openSocket(again.url);
    const restored = await request(ws, { cmd: 'get_state' });
    ws.close();
    await again.stop();
    assert.equal(restored.seq, final.seq);
    assert.deepEqual(restored.design, final.design);
    console.log(`soak: ${acked.length} acknowledged edits by ${SOAK_CLIENTS} clients in ${SOAK_SECONDS} s, all restored after SIGKILL; ` +
      `RSS MiB first ${rss[0].toFixed(1)}, second-quarter median ${warm.toFixed(1)}, last-quarter median ${last.toFixed(1)}, ` +
      `max ${Math.max(...rss).toFixed(1)} (${rss.length} samples)`);
  } catch (e) {
    e.message += `\nthe server printed:\n${soak.output()}`;
    throw e;
  } finally {
    // A failure above must not leave the sampler or the sockets keeping this file's process alive.
    clearInterval(sampler);
    for (const ws of clients) ws.close();
    await soak.stop();
  }
});

test(`SIGKILL during a scripted edit stream, ${KILL_ROUNDS} times, loses no acknowledged edit`, { timeout: (KILL_ROUNDS * 30 + 60) * 1000 }, async () => {
  const session = freshSessionDir('kill');
  const acked = new Map();  // "round,client,i" -> seq of the acknowledged add_control_point
  let lastSeq = 0;
  let sent = 0;
  for (let round = 0; round < KILL_ROUNDS; round++) {
    const srv = await startServer({ bin: tools.bin, session, model: round === 0 ? 'abdomen' : null });
    try {
      const clients = await Promise.all(Array.from({ length: 4 }, () => openSocket(srv.url)));
      // The reopened session must hold every edit acknowledged before the kill.
      const state = await request(clients[0], { cmd: 'get_state' });
      assert.ok(state.seq >= lastSeq, `round ${round}: seq ${state.seq} < last acknowledged ${lastSeq}`);
      const present = new Set(state.design.control_points.map((p) => p.position_mm.join(',')));
      for (const key of acked.keys()) assert.ok(present.has(key), `round ${round}: acknowledged edit ${key} was lost`);
      // Edit streams on every client; SIGKILL at a moment that varies with the round.
      const killAt = Date.now() + 300 + ((round * 397) % 1200);
      const streams = clients.map(async (ws, c) => {
        for (let i = 0; ; i++) {
          const key = `${round},${c},${i}`;
          sent++;
          try {
            const r = await request(ws, { cmd: 'add_control_point', position_mm: [round, c, i], langer_kPa: 1 + (i % 7), cross_kPa: 1 });
            assert.equal(r.type, 'ack', JSON.stringify(r));
            acked.set(key, r.seq);
            lastSeq = Math.max(lastSeq, r.seq);
          } catch (e) {
            if (/connection closed/.test(e.message)) return;  // killed while this edit was in flight
            throw e;
          }
        }
      });
      await new Promise((resolve) => setTimeout(resolve, Math.max(0, killAt - Date.now())));
      const exited = await srv.kill();
      assert.equal(exited.signal, 'SIGKILL');
      await Promise.all(streams);
    } finally {
      await srv.stop();
    }
  }
  // Final reopen: every acknowledged edit is there, the seqs are consistent, the journal is whole.
  const again = await startServer({ bin: tools.bin, session, model: null });
  try {
    const ws = await openSocket(again.url);
    const state = await request(ws, { cmd: 'get_state' });
    ws.close();
    const present = new Set(state.design.control_points.map((p) => p.position_mm.join(',')));
    for (const key of acked.keys()) assert.ok(present.has(key), `acknowledged edit ${key} was lost`);
    assert.ok(state.seq >= lastSeq);
    assert.equal(new Set(acked.values()).size, acked.size, 'every acknowledged seq is unique');
    const lines = fs.readFileSync(`${session}/journal.jsonl`, 'utf8').split('\n').filter((l) => l.length > 0);
    assert.equal(lines.length, state.seq, 'one journal line per edit');
    lines.forEach((l, n) => assert.equal(JSON.parse(l).seq, n + 1));
    console.log(`kill: ${KILL_ROUNDS} SIGKILLs during edit streams; ${acked.size} of ${sent} edits acknowledged, all restored; ` +
      `${state.seq - acked.size} unacknowledged but journaled edits kept`);
  } finally {
    await again.stop();
  }
});
