// The engine's thread: the WebAssembly module runs here so the page never freezes. Messages
// in: {id, cmd, source, origin, options} (cmd "commands": source is a script of pdyn kin /
// pdyn dsolve lines); out: {id, type: "progress", done, all},
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
      case "commands":
        text = pdyn.commands(source, origin);
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

// A first call pays for V8 compiling the functions it reaches (parser, derivation,
// integrator, JSON): a small run right after loading does that while the reader looks at the
// page, so the first click is as fast as the next ones. Its result is discarded.
const WARM_UP = `name = "warm-up"
[parameters]
GM = 1.0
[coordinates]
x = { initial = 1.0, rate = 0.0 }
y = { initial = 0.0, rate = 1.0 }
[particles.p]
mass = "1"
position = "[x, y, 0]"
[points]
O = "[0, 0, 0]"
[[forces]]
kind = "inverse_square"
on = "p"
to = "O"
strength = "GM"
[simulate]
t_end = 1.0
`;

ready.then(() => {
  self.postMessage({ type: "ready", version: pdyn.version() });
  const answers = [pdyn.derive(WARM_UP, "warm-up", '{"json": true}'), pdyn.run(WARM_UP, "warm-up", "{}", null)];
  // A warm-up that fails means the engine is broken: say so in the console.
  for (const a of answers) if (!JSON.parse(a).ok) console.error("pdyn warm-up failed:", a);
});
