// The engine in a Web Worker: one command at a time, cancellable (the worker is terminated
// and a fresh one started), progress forwarded. A panic in the module ("internal error")
// also replaces the worker, since a trapped WebAssembly instance is not reused.
export class Engine {
  constructor(onReady) {
    this.onReady = onReady;
    this.nextId = 1;
    this.pending = null;
    this.start();
  }

  start() {
    this.worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module" });
    this.ready = new Promise((resolve) => {
      this.worker.addEventListener("message", (e) => {
        if (e.data.type === "ready") {
          resolve(e.data.version);
          this.onReady?.(e.data.version);
        }
      });
    });
    this.worker.addEventListener("message", (e) => this.receive(e.data));
  }

  receive(msg) {
    const p = this.pending;
    if (!p || msg.id !== p.id) return;
    if (msg.type === "progress") {
      p.onProgress?.(msg.done, msg.all);
    } else if (msg.type === "result") {
      this.pending = null;
      let value;
      try {
        value = JSON.parse(msg.text);
      } catch (err) {
        value = { ok: false, error: { kind: "internal", message: `unreadable answer: ${err}` } };
      }
      p.resolve({ value, ms: msg.ms });
    } else if (msg.type === "crash") {
      this.pending = null;
      this.worker.terminate();
      this.start();
      p.resolve({ value: { ok: false, error: { kind: "internal", message: msg.message } }, ms: 0 });
    }
  }

  /** Runs `cmd` ("run", "derive", …) on the model text; resolves to {value, ms}. */
  call(cmd, source, origin, options, onProgress) {
    if (this.pending) this.cancel();
    const id = this.nextId++;
    return new Promise((resolve) => {
      this.pending = { id, resolve, onProgress };
      this.worker.postMessage({ id, cmd, source, origin, options });
    });
  }

  /** Stops the current command; its promise resolves as cancelled. */
  cancel() {
    const p = this.pending;
    if (!p) return;
    this.pending = null;
    this.worker.terminate();
    this.start();
    p.resolve({ value: { ok: false, cancelled: true }, ms: 0 });
  }
}
