// The WebSocket to the studio server: request/reply matching by "req", pushes dispatched by
// "type", and automatic reconnection (a client that reconnects says hello and resumes). Results
// and frames arrive as binary messages whose packed arrays become typed arrays (packed.js).
import { decodeMessage } from './packed.js';

export class Connection {
  constructor(url, onMessage, onStatus) {
    this.url = url;
    this.onMessage = onMessage;
    this.onStatus = onStatus;
    this.nextReq = 1;
    this.pending = new Map();
    this.backoffMs = 250;
    this.lastDecodeMs = 0;
    this.open();
  }

  open() {
    const ws = new WebSocket(this.url);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    ws.onopen = () => {
      this.backoffMs = 250;
      this.onStatus(true);
      this.request('hello').catch(() => {});
    };
    ws.onmessage = (event) => {
      let message;
      const start = performance.now();
      try {
        message = decodeMessage(event.data);
      } catch (e) {
        console.error(`studio: a message from the server could not be read: ${e.message}`);
        return;
      }
      this.lastDecodeMs = performance.now() - start;  // parse and unpack of the last message
      if (message.req !== undefined && this.pending.has(message.req)) {
        const { resolve, reject } = this.pending.get(message.req);
        this.pending.delete(message.req);
        if (message.type === 'error') reject(new Error(message.message)); else resolve(message);
      }
      this.onMessage(message);
    };
    ws.onclose = () => {
      this.onStatus(false);
      for (const { reject } of this.pending.values()) reject(new Error('connection lost'));
      this.pending.clear();
      setTimeout(() => this.open(), this.backoffMs);
      this.backoffMs = Math.min(this.backoffMs * 2, 4000);
    };
  }

  get connected() { return this.ws && this.ws.readyState === WebSocket.OPEN; }

  /// Sends {cmd, ...fields, req} and resolves with the reply (rejects on an error reply).
  request(cmd, fields = {}) {
    if (!this.connected) return Promise.reject(new Error('not connected'));
    const req = this.nextReq++;
    return new Promise((resolve, reject) => {
      this.pending.set(req, { resolve, reject });
      this.ws.send(JSON.stringify({ ...fields, cmd, req }));
    });
  }
}
