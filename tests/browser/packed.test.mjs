// The page's reader of the studio's messages (web/js/packed.js, format of
// apps/studio/wire_message.hpp): JSON text passes through; a binary message's packed arrays become
// typed-array views at their offsets after the padded header; damaged messages are named.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { decodeMessage } from '../../web/js/packed.js';

/// A binary message as the server writes it: "CLV1", header length, header, padding, arrays.
function binaryMessage(header, arrays) {
  const text = new TextEncoder().encode(JSON.stringify(header));
  const start = Math.ceil((8 + text.length) / 4) * 4;
  const bytes = new Uint8Array(start + arrays.byteLength);
  bytes.set(new TextEncoder().encode('CLV1'), 0);
  new DataView(bytes.buffer).setUint32(4, text.length, true);
  bytes.set(text, 8);
  bytes.set(new Uint8Array(arrays.buffer, arrays.byteOffset, arrays.byteLength), start);
  return bytes.buffer;
}

test('JSON text passes through', () => {
  assert.deepEqual(decodeMessage('{"type":"state","seq":3}'), { type: 'state', seq: 3 });
});

test('packed arrays become typed arrays at their offsets, nested in objects and arrays', () => {
  const arrays = new Float32Array([1.5, -2, 3.25, 0.125, 7, 9]);
  new Uint32Array(arrays.buffer, 20, 1)[0] = 4294967295;  // the last value, as u32
  const header = {
    type: 'result', seq: 7, timings_ms: { total: 12.5 },
    surface: { positions_mm: { packed: 'f32', count: 3, offset: 0 } },
    streamlines_mm: [{ packed: 'f32', count: 2, offset: 12 }, { packed: 'u32', count: 1, offset: 20 }],
  };
  const m = decodeMessage(binaryMessage(header, arrays));
  assert.equal(m.seq, 7);
  assert.equal(m.timings_ms.total, 12.5);
  assert.ok(m.surface.positions_mm instanceof Float32Array);
  assert.deepEqual(Array.from(m.surface.positions_mm), [1.5, -2, 3.25]);
  assert.deepEqual(Array.from(m.streamlines_mm[0]), [0.125, 7]);
  assert.ok(m.streamlines_mm[1] instanceof Uint32Array);
  assert.equal(m.streamlines_mm[1][0], 4294967295);
});

test('damaged binary messages are named', () => {
  const arrays = new Float32Array([1, 2]);
  assert.throws(() => decodeMessage(new Uint8Array([1, 2, 3]).buffer), /binary message of 3 bytes without the CLV1 header/);
  assert.throws(() => decodeMessage(binaryMessage({ a: { packed: 'f32', count: 3, offset: 0 } }, arrays)),
    /packed f32 array of 3 values at offset 0 does not fit the message/);
  assert.throws(() => decodeMessage(binaryMessage({ a: { packed: 'f32', count: 1, offset: 2 } }, arrays)),
    /packed f32 array of 1 values at offset 2 does not fit the message/);
  assert.throws(() => decodeMessage(binaryMessage({ a: { packed: 'f64', count: 1, offset: 0 } }, arrays)),
    /packed array of unknown kind 'f64'/);
  const long = new Uint8Array(binaryMessage({ a: 1 }, arrays));
  new DataView(long.buffer).setUint32(4, 1000, true);
  assert.throws(() => decodeMessage(long.buffer), /a header of 1000 bytes runs past its end/);
});
