// Packed numeric arrays of the studio's messages (apps/studio/packed_array.hpp):
// {"packed": "f32" | "u32", "count": n, "base64": "..."} becomes a Float32Array / Uint32Array.
// A message is unpacked once, where it arrives (connection.js); the rest of the page sees typed
// arrays where the server packed and plain arrays where it did not (a field with a NaN stays a
// JSON array and the server turns the message into an error before it leaves).

const TYPES = { f32: Float32Array, u32: Uint32Array };

function bytesOf(base64) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(base64);
  const text = atob(base64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  return bytes;
}

function isPacked(v) {
  return v !== null && typeof v === 'object' && !Array.isArray(v) && typeof v.packed === 'string' && typeof v.base64 === 'string';
}

/// The typed array of one packed value; throws on a kind or size that does not fit.
export function unpackArray(v) {
  const Type = TYPES[v.packed];
  if (!Type) throw new Error(`packed array of unknown kind '${v.packed}'`);
  const bytes = bytesOf(v.base64);
  if (bytes.length !== v.count * Type.BYTES_PER_ELEMENT) throw new Error(`packed ${v.packed} array: ${bytes.length} bytes for ${v.count} values`);
  return new Type(bytes.buffer, bytes.byteOffset, v.count);
}

/// Replaces every packed array inside `message` (objects and arrays of objects, in place).
export function unpackMessage(message) {
  if (message === null || typeof message !== 'object') return message;
  if (Array.isArray(message)) {
    for (let i = 0; i < message.length; i++) {
      const v = message[i];
      if (v === null || typeof v !== 'object') return message;  // an array of numbers: nothing packed inside
      message[i] = isPacked(v) ? unpackArray(v) : unpackMessage(v);
    }
    return message;
  }
  for (const key of Object.keys(message)) {
    const v = message[key];
    if (v !== null && typeof v === 'object') message[key] = isPacked(v) ? unpackArray(v) : unpackMessage(v);
  }
  return message;
}
