// The engine's thread: the WebAssembly module runs here so the page never freezes. Messages
// in: {id, cmd, source, origin, options}; out: {id, type: "progress", done, all},
// {id, type: "result", text, ms} (text: the JSON the module returned), or {id, type: "crash",
// message} after a panic (the page then starts a fresh worker: a trapped instance is not
// reused). Cancelling is the page terminating this worker.
import init, * as pdyn from "./wasm/pdyn_web.js";

const ready = init();

self.onmessage = async (event) => {
  const { id, cmd, source, origin, options } = event.data;
  await ready;
  const progress = (done, all) => self.postMessage({ id, type: "progress", done, all });
  const t0 = performance.now();
  try {
    let text;
    const opts = JSON.stringify(options ?? {});
    switch (cmd) {
      case "run":
        text = pdyn.run(source, origin, opts, progress);
        break;
      case "sweep":
        text = pdyn.sweep(source, origin, opts, progress);
        break;
      case "derive":
        text = pdyn.derive(source, origin, opts);
        break;
      case "forces":
        text = pdyn.forces(source, origin, opts);
        break;
      case "check":
        text = pdyn.check(source, origin, opts);
        break;
      case "kind":
        text = pdyn.kind(source, origin);
        break;
      case "methods":
        text = pdyn.methods_help(source, origin);
        break;
      default:
        text = JSON.stringify({ ok: false, error: { kind: "argument", message: `unknown command ${cmd}` } });
    }
    self.postMessage({ id, type: "result", text, ms: performance.now() - t0 });
  } catch (e) {
    let message = String(e && e.message ? e.message : e);
    try {
      message = pdyn.take_panic() ?? message;
    } catch (_) {
      // The instance is gone; the trap's own message stays.
    }
    self.postMessage({ id, type: "crash", message });
  }
};

ready.then(() => self.postMessage({ type: "ready", version: pdyn.version() }));
