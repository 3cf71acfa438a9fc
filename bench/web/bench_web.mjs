// The playground measured in headless Chromium, whole page, on localhost (web/dist served
// gzip'd by web/tests/server.mjs):
//   - first load: bytes transferred (wasm + JS + CSS, gzip) and time until the page is
//     interactive (engine ready, model loaded), fresh browser each time;
//   - the satellite example from click to plotted result (the Run button's handler to the
//     plots drawn), first click and the median of the next ones;
//   - the interpreter in WebAssembly against the native binary's `--no-jit` on the same models
//     (engine time in the page vs `pdyn run --no-jit --json` whole process, release build).
//
//   scripts/build-web.sh && cargo build --release -p pdyn-cli
//   node bench/web/bench_web.mjs [runs]
import { execFileSync } from "node:child_process";
import path from "node:path";
import { serve } from "../../web/tests/server.mjs";
import { launch, open, command } from "../../web/tests/browser.mjs";

const root = path.resolve(new URL("../..", import.meta.url).pathname);
const runs = Number(process.argv[2] ?? 7);
const bin = process.env.PDYN_BIN ?? path.join(root, "target", "release", "pdyn");
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];

const server = await serve(path.join(root, "web", "dist"));
const out = {};
try {
  // First load, fresh browser each time.
  const loads = [];
  let bytes = 0;
  for (let i = 0; i < 3; i++) {
    const { browser, close } = await launch();
    const before = server.sent.gzip;
    const t0 = performance.now();
    const { page } = await open(browser, server.url);
    loads.push(performance.now() - t0);
    bytes = server.sent.gzip - before;
    await close();
  }
  out.first_load_bytes_gzip = bytes;
  out.first_load_interactive_ms = median(loads);

  const { browser, close } = await launch();
  try {
    const { page } = await open(browser, server.url, "#example=examples/satellite.toml");
    const clicks = [];
    for (let i = 0; i < runs; i++) {
      await command(page, "run");
      // The status line is written after the plots are drawn: click to plotted result.
      clicks.push(await page.evaluate(() => Number(document.body.dataset.lastMs)));
    }
    out.satellite_first_click_ms = clicks[0];
    out.satellite_click_to_plot_ms_median = median(clicks.slice(1));

    // Interpreter: wasm engine time vs native --no-jit whole process, on runs long enough
    // that the process's start (a few ms) does not decide the ratio; the same options in both.
    out.interpreter = [];
    const cases = [
      ["examples/satellite.toml", { t_end: "10000" }],
      ["examples/pendulum_chain_3.toml", { t_end: "100" }],
      ["examples/hanging_net.toml", {}],
      ["examples/md/lj_liquid.toml", { set: "n=5", t_end: "5" }],
    ];
    for (const [ex, opts] of cases) {
      const p = (await open(browser, server.url, `#example=${ex}`)).page;
      await p.fill("#opt-t_end", opts.t_end ?? "");
      await p.fill("#opt-set", opts.set ?? "");
      const engine = [];
      for (let i = 0; i < 3; i++) {
        await command(p, "run");
        engine.push(await p.evaluate(() => Number(document.getElementById("status").textContent.match(/engine (\d+) ms/)[1])));
      }
      const args = ["run", ex, "--no-jit", "--json"];
      if (opts.t_end) args.push("--t-end", opts.t_end);
      if (opts.set) args.push("--set", opts.set);
      const native = [];
      for (let i = 0; i < 3; i++) {
        const t0 = performance.now();
        execFileSync(bin, args, { cwd: root, stdio: ["ignore", "ignore", "ignore"] });
        native.push(performance.now() - t0);
      }
      out.interpreter.push({ model: ex, options: opts, wasm_ms: median(engine), native_no_jit_ms: median(native), ratio: median(engine) / median(native) });
      await p.close();
    }
  } finally {
    await close();
  }
} finally {
  await server.close();
}
console.log(JSON.stringify(out, null, 2));
