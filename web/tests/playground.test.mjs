// The playground in headless Chromium (scripts/test-web.sh builds web/dist and runs these):
// every example loads, derives and runs in the page with the numbers of the CLI's
// `--no-jit --json`; a broken model shows a located error in the editor; the URL carries a
// model; keyboard use; cancelling a long run.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { serve } from "./server.mjs";
import { launch, open, command } from "./browser.mjs";
import { compare } from "./compare.mjs";

const root = path.resolve(new URL("../..", import.meta.url).pathname);
const dist = path.join(root, "web", "dist");
const bin = process.env.PDYN_BIN ?? path.join(root, "target", "debug", "pdyn");

// How closely each example's page numbers follow the CLI's. The WebAssembly build's
// transcendental functions (pow, sin, exp, …) are Rust's libm port, the CLI's are glibc's:
// they differ in the last bit of some results, so runs that call them agree to round-off, not
// bit for bit. Runs whose arithmetic is IEEE-exact (+ − × ÷ √, integer powers) are identical.
// Stochastic and chaotic runs amplify the last bit over many steps: compared statistically.
const IDENTICAL = new Set([
  "examples/chain_modes.toml",
  "examples/contact/block_sliding.toml",
  "examples/contact/two_balls.toml",
  "examples/kremlin_stone.toml",
  "examples/nanoparticle.toml",
  "examples/nbody/figure_eight.toml",
  "examples/nbody/figure_eight_precise.toml",
  "examples/pulley.toml",
]);
// Chaotic motion (the double and triple pendulum released at large angles): a last-bit
// difference grows by orders of magnitude over the run, as it would between two compilers.
// The bouncing ball's Zeno ratio is estimated from the last impacts before the accumulation
// point, where velocities are tiny and round-off is relatively large.
const CHAOTIC = new Set(["examples/pendulum_chain_2.toml", "examples/pendulum_chain_3.toml", "examples/contact/bouncing_ball.toml"]);
// Langevin / melting runs: thousands of steps of a chaotic system with a random force.
const STATISTICAL = new Set(["examples/md/argon_melting.toml", "examples/md/polymer_melt.toml"]);
// Files the browser cannot read (the model names another file on disk).
const NEEDS_FILES = new Set(["examples/nbody/outer_solar_system_csv.toml"]);

const examples = (function list(dir) {
  return fs
    .readdirSync(path.join(root, dir), { withFileTypes: true })
    .flatMap((e) => (e.isDirectory() ? list(path.join(dir, e.name)) : e.name.endsWith(".toml") ? [path.join(dir, e.name)] : []))
    .sort();
})("examples");

let server;
let chromium;
before(async () => {
  assert.ok(fs.existsSync(path.join(dist, "index.html")), "web/dist is not built: run scripts/build-web.sh");
  assert.ok(fs.existsSync(bin), `no pdyn binary at ${bin} (cargo build -p pdyn-cli, or set PDYN_BIN)`);
  server = await serve(dist);
  chromium = await launch();
});
after(async () => {
  await chromium?.close();
  await server?.close();
});

function cli(args) {
  try {
    return JSON.parse(execFileSync(bin, args, { cwd: root, encoding: "utf8", stdio: ["ignore", "pipe", "ignore"] }));
  } catch (e) {
    return JSON.parse(e.stdout);
  }
}

/** Numbers within round-off: |a − b| ≤ tol · max(1, |a|, |b|) for every differing value.
 * An ulp in the step-size controller's `pow` can flip one accept/reject decision, so the
 * step statistics and output rows may differ by a few (≤ 2 %); texts and other counts not. */
function assertClose(stats, tol, where) {
  const real = stats.mismatches.filter((m) => {
    const c = /^(stats\.\w+|outputs|rows): (\d+) ≠ (\d+)$/.exec(m);
    return !(c && Math.abs(c[2] - c[3]) <= Math.max(2, 0.02 * Number(c[3])));
  });
  assert.deepEqual(real, [], `${where}: counts or texts differ`);
  assert.ok(stats.maxScaled <= tol, `${where}: ${stats.worst}`);
}

test("the page loads, shows the default example and the engine is WebAssembly", async () => {
  const { page, errors } = await open(chromium.browser, server.url);
  const text = await page.evaluate(() => window.pdynEditor.text);
  assert.match(text, /Satellite orbit/);
  assert.match(await page.textContent("#engine-status"), /WebAssembly/);
  assert.deepEqual(errors, []);
  await page.close();
});

for (const ex of examples) {
  test(`${ex}: loads, derives and runs with the CLI's numbers`, async () => {
    const source = fs.readFileSync(path.join(root, ex), "utf8");
    const kind = /^\[nbody\]/m.test(source) ? "nbody" : /^\[md\]/m.test(source) ? "md" : "mechanics";
    const runs = kind !== "mechanics" || /^\[simulate\]/m.test(source);
    const { page, errors } = await open(chromium.browser, server.url, `#example=${ex}`);
    assert.equal(await page.evaluate(() => document.getElementById("example").value), ex);
    if (kind === "mechanics") {
      // Derive: the equations typeset, and the same derivation as `pdyn derive --json`.
      const d = await command(page, "derive");
      assert.ok(d?.value?.ok, `${ex}: derive failed: ${await page.textContent("#error")}`);
      assert.ok((await page.locator("#view-equations .katex").count()) > 0, `${ex}: no equation typeset`);
      const want = cli(["derive", ex, "--json"]);
      assert.deepEqual(d.value.derivation.equations, want.equations, `${ex}: equations differ from the CLI's`);
    }
    if (NEEDS_FILES.has(ex)) {
      const r = await command(page, "run");
      assert.equal(r, null);
      const box = page.locator("#error");
      assert.match(await box.textContent(), /cannot read the bodies file .* not supported on this platform/);
      assert.ok(Number(await box.getAttribute("data-line")) > 0, "the error is located");
      assert.equal(await page.locator(".cm-error-line").count(), 1);
      await page.close();
      return;
    }
    if (runs) {
      const r = await command(page, "run");
      assert.ok(r?.value?.ok, `${ex}: run failed: ${await page.textContent("#error")}`);
      const mine = JSON.parse(r.value.summary_text);
      // The browser's default sizes (the "set" box) go to the CLI too.
      const set = (await page.inputValue("#opt-set")).replace(/\s+/g, "");
      const want = cli(["run", ex, "--no-jit", "--json", ...(set ? ["--set", set] : [])]);
      const s = compare(mine, want);
      if (IDENTICAL.has(ex)) {
        assert.deepEqual(s.mismatches, []);
        assert.equal(s.differing, 0, `${ex}: expected bit-identical numbers; ${s.worst}`);
      } else if (STATISTICAL.has(ex)) {
        // Same run length and records; the thermodynamics agree to a few per cent.
        assert.equal(mine.steps, want.steps);
        for (const key of ["temperature", "potential_per_atom"]) {
          const a = mine.averages?.[key]?.mean;
          const b = want.averages?.[key]?.mean;
          if (a === undefined && b === undefined) continue;
          assert.ok(Math.abs(a - b) <= 0.05 * Math.abs(b), `${ex}: ${key} ${a} vs ${b}`);
        }
      } else {
        assertClose(s, CHAOTIC.has(ex) ? 1e-5 : 1e-9, ex);
      }
      // The views: plots drawn; the animation has frames for the particles.
      assert.ok((await page.locator("#view-plots .uplot").count()) > 0, `${ex}: no plot`);
      const frames = await page.evaluate(() => Number(document.getElementById("frame").max));
      if (kind !== "md" || /dump_every/.test(source)) assert.ok(frames > 0, `${ex}: nothing to animate`);
    } else {
      const mine = await page.evaluate(
        ([text, origin]) => window.pdynEngine.call("forces", text, origin, { json: true }),
        [source, ex],
      );
      assert.ok(mine.value.ok, `${ex}: forces failed: ${JSON.stringify(mine.value.error)}`);
      const s = compare(mine.value.result, cli(["forces", ex, "--json"]));
      assertClose(s, 1e-9, ex);
    }
    assert.deepEqual(errors, []);
    await page.close();
  });
}

test("a broken model shows its loader's error at the line and column, in the editor", async () => {
  const { page } = await open(chromium.browser, server.url, "#example=examples/satellite.toml");
  const broken = fs.readFileSync(path.join(root, "examples/satellite.toml"), "utf8").replace('strength = "GM*m"', 'strength = "GM*m*"');
  await page.evaluate((t) => (window.pdynEditor.text = t), broken);
  await command(page, "run");
  const box = page.locator("#error");
  assert.equal(await box.isHidden(), false);
  const line = broken.split("\n").findIndex((l) => l.includes('strength = "GM*m*"')) + 1;
  assert.equal(Number(await box.getAttribute("data-line")), line);
  assert.match(await box.textContent(), /strength/);
  const marked = await page.evaluate(() => {
    const el = document.querySelector(".cm-error-line");
    return el ? el.textContent : null;
  });
  assert.match(marked, /strength = "GM\*m\*"/);
  await page.close();
});

test("the URL carries the model: a copied link reopens the same text", async () => {
  const { page } = await open(chromium.browser, server.url, "#example=examples/pulley.toml");
  const edited = fs.readFileSync(path.join(root, "examples/pulley.toml"), "utf8") + "\n# edited: ünïcødé and a long line " + "x".repeat(500) + "\n";
  await page.evaluate((t) => (window.pdynEditor.text = t), edited);
  await page.click("#share");
  await page.waitForFunction(() => location.hash.startsWith("#model="));
  const hash = await page.evaluate(() => location.hash);
  const { page: second } = await open(chromium.browser, server.url, hash);
  const text = await second.evaluate(() => window.pdynEditor.text);
  assert.equal(text, edited);
  // A cut link says so instead of loading a broken model silently.
  const { page: third } = await open(chromium.browser, server.url, hash.slice(0, hash.length / 2));
  assert.match(await third.textContent("#error"), /could not be read/);
  await Promise.all([page.close(), second.close(), third.close()]);
});

test("keyboard: Tab reaches the commands, Enter runs, arrow keys switch views", async () => {
  const { page } = await open(chromium.browser, server.url, "#example=examples/satellite.toml");
  await page.focus("#run");
  await page.keyboard.press("Enter");
  await page.waitForFunction(() => document.body.dataset.lastCommand === "run");
  await page.focus("#tab-plots");
  await page.keyboard.press("ArrowRight");
  assert.equal(await page.getAttribute("#tab-animation", "aria-selected"), "true");
  assert.equal(await page.locator("#view-animation").isHidden(), false);
  // Every control has an accessible name.
  const unnamed = await page.evaluate(() =>
    [...document.querySelectorAll("button, select, input")].filter((el) => {
      const label = el.labels?.[0]?.textContent || el.getAttribute("aria-label") || el.textContent;
      return !label || !label.trim();
    }).map((el) => el.id),
  );
  assert.deepEqual(unnamed, []);
  await page.close();
});

test("a long run can be cancelled and the page stays responsive", async () => {
  const { page } = await open(chromium.browser, server.url, "#example=examples/md/lj_liquid.toml");
  await page.fill("#opt-t_end", "500");
  await page.click("#run");
  await page.waitForFunction(() => document.body.dataset.busy === "true");
  await page.waitForTimeout(300);
  // The page answers while the worker computes.
  assert.equal(await page.evaluate(() => 6 * 7), 42);
  await page.click("#cancel");
  await page.waitForFunction(() => document.getElementById("status").textContent === "cancelled");
  // A fresh worker runs the next command.
  await page.selectOption("#example", "examples/satellite.toml");
  await page.fill("#opt-t_end", "");
  const r = await command(page, "run");
  assert.ok(r.value.ok);
  await page.close();
});
