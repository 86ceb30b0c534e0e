// The studio's messages as they arrive (apps/studio/wire_message.hpp): JSON text, or, for
// messages with packed arrays (results, frames), one binary message:
//   "CLV1", uint32 n, n bytes of JSON, zero padding to a multiple of 4, the arrays' bytes.
// In the JSON each packed array is {"packed": "f32" | "u32", "count": c, "offset": o}; it
// becomes a Float32Array / Uint32Array view on the received buffer at (start of the arrays) + o:
// nothing is copied or parsed per number. The rest of the page sees typed arrays where the server
// packed and plain arrays where it did not (a field with a NaN stays a JSON array and the server
// turns the message into an error before it leaves).

const TYPES = { f32: Float32Array, u32: Uint32Array };
const MAGIC = 'CLV1';
const PREFIX_BYTES = 8;
const decoder = new TextDecoder();

function isPacked(v) {
  return v !== null && typeof v === 'object' && !Array.isArray(v) && typeof v.packed === 'string' && typeof v.offset === 'number';
}

/// The typed array of one packed value in `buffer`'s arrays (from byte `start`); throws on a kind,
/// size or offset that does not fit.
function viewOf(v, buffer, start) {
  const Type = TYPES[v.packed];
  if (!Type) throw new Error(`packed array of unknown kind '${v.packed}'`);
  const at = start + v.offset;
  if (v.offset % Type.BYTES_PER_ELEMENT !== 0 || !Number.isInteger(v.count) || v.count < 0 ||
      at + v.count * Type.BYTES_PER_ELEMENT > buffer.byteLength) {
    throw new Error(`packed ${v.packed} array of ${v.count} values at offset ${v.offset} does not fit the message`);
  }
  return new Type(buffer, at, v.count);
}

/// Replaces every packed array inside `message` (objects and arrays of objects, in place).
function unpackInto(message, buffer, start) {
  if (message === null || typeof message !== 'object') return message;
  if (Array.isArray(message)) {
    for (let i = 0; i < message.length; i++) {
      const v = message[i];
      if (v === null || typeof v !== 'object') return message;  // an array of numbers: nothing packed inside
      message[i] = isPacked(v) ? viewOf(v, buffer, start) : unpackInto(v, buffer, start);
    }
    return message;
  }
  for (const key of Object.keys(message)) {
    const v = message[key];
    if (v !== null && typeof v === 'object') message[key] = isPacked(v) ? viewOf(v, buffer, start) : unpackInto(v, buffer, start);
  }
  return message;
}

/// The message in `data`: a string (JSON text) or an ArrayBuffer (the binary form).
export function decodeMessage(data) {
  if (typeof data === 'string') return JSON.parse(data);
  const bytes = new Uint8Array(data);
  if (bytes.length < PREFIX_BYTES || decoder.decode(bytes.subarray(0, 4)) !== MAGIC) {
    throw new Error(`binary message of ${bytes.length} bytes without the ${MAGIC} header`);
  }
  const headerBytes = new DataView(data).getUint32(4, true);
  if (PREFIX_BYTES + headerBytes > bytes.length) throw new Error(`binary message: a header of ${headerBytes} bytes runs past its end`);
  const message = JSON.parse(decoder.decode(bytes.subarray(PREFIX_BYTES, PREFIX_BYTES + headerBytes)));
  const start = Math.ceil((PREFIX_BYTES + headerBytes) / 4) * 4;
  return unpackInto(message, data, start);
}
