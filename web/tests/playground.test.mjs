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

// The page's numbers are the CLI's, bit for bit: the same code, and every transcendental
// function (sin, exp, pow, …) from the `libm` crate in both builds (clippy.toml forbids std's,
// which call glibc natively and a libm port in WebAssembly). Chaotic and stochastic runs too:
// the same seeds, the same arithmetic in the same order.
// Files the browser cannot read (the model names another file on disk).
const NEEDS_FILES = new Set(["examples/nbody/outer_solar_system_csv.toml", "examples/data/earthquake.toml", "examples/hanging_net_tables.toml", "examples/truss_tables.toml"]);

const examples = (function list(dir) {
  return fs
    .readdirSync(path.join(root, dir), { withFileTypes: true })
    .flatMap((e) => (e.isDirectory() ? list(path.join(dir, e.name)) : e.name.endsWith(".toml") ? [path.join(dir, e.name)] : []))
    .filter((f) => !f.startsWith(path.join("examples", "large")))
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

test("the page loads, shows the default example and the engine is WebAssembly", async () => {
  const { page, errors } = await open(chromium.browser, server.url);
  const text = await page.evaluate(() => window.pdynEditor.text);
  assert.match(text, /Satellite orbit/);
  assert.match(await page.textContent("#engine-status"), /WebAssembly/);
  assert.deepEqual(errors, []);
  await page.close();
});

for (const ex of examples) {
  test(`${ex}: loads, derives and runs with the CLI's numbers`, async (t) => {
    const source = fs.readFileSync(path.join(root, ex), "utf8");
    const kind = /^\[nbody\]/m.test(source) ? "nbody" : /^\[md\]/m.test(source) ? "md" : "mechanics";
    const runs = kind !== "mechanics" || /^\[simulate\]/m.test(source);
    const { page, errors } = await open(chromium.browser, server.url, `#example=${ex}`);
    assert.equal(await page.evaluate(() => document.getElementById("example").value), ex);
    if (NEEDS_FILES.has(ex)) {
      const r = await command(page, "run");
      assert.equal(r, null);
      const box = page.locator("#error");
      assert.match(await box.textContent(), /cannot read the (bodies|data|table) file .* not supported on this platform/);
      assert.ok(Number(await box.getAttribute("data-line")) > 0, "the error is located");
      assert.equal(await page.locator(".cm-error-line").count(), 1);
      await page.close();
      return;
    }
    if (kind === "mechanics") {
      // Derive: the equations typeset, and the same derivation as `pdyn derive --json`.
      const d = await command(page, "derive");
      assert.ok(d?.value?.ok, `${ex}: derive failed: ${await page.textContent("#error")}`);
      assert.ok((await page.locator("#view-equations .katex").count()) > 0, `${ex}: no equation typeset`);
      const want = cli(["derive", ex, "--json"]);
      assert.deepEqual(d.value.derivation.equations, want.equations, `${ex}: equations differ from the CLI's`);
    }
    if (runs) {
      const r = await command(page, "run");
      assert.ok(r?.value?.ok, `${ex}: run failed: ${await page.textContent("#error")}`);
      const mine = JSON.parse(r.value.summary_text);
      // The browser's default sizes (the "set" box) go to the CLI too.
      const set = (await page.inputValue("#opt-set")).replace(/\s+/g, "");
      const want = cli(["run", ex, "--no-jit", "--json", ...(set ? ["--set", set] : [])]);
      const s = compare(mine, want);
      t.diagnostic(`${s.identical} numbers identical, ${s.differing} differing (largest ${s.maxScaled.toExponential(1)}: ${s.worst})`);
      assert.deepEqual(s.mismatches, [], `${ex}: counts or texts differ`);
      assert.equal(s.differing, 0, `${ex}: expected bit-identical numbers; ${s.worst}`);
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
      assert.deepEqual(s.mismatches, [], `${ex}: counts or texts differ`);
      // As for kin and dsolve: an ulp or two in places, not yet bit for bit.
      assert.ok(s.maxScaled <= 1e-13, `${ex}: ${s.worst}`);
    }
    assert.deepEqual(errors, []);
    await page.close();
  });
}

// The kin and dsolve scripts: the page splits each line into words and runs it; a real shell
// runs the same script with `pdyn` as a function adding `--json`. Same outputs, line by line.
const scripts = ["examples/kin", "examples/dsolve"].flatMap((d) =>
  fs
    .readdirSync(path.join(root, d))
    .filter((f) => f.endsWith(".sh"))
    .sort()
    .map((f) => `${d}/${f}`),
);

function shellJson(script) {
  const out = execFileSync("sh", ["-c", 'pdyn() { sub="$1"; shift; "$PDYN" "$sub" --json "$@"; }; . "./$0"', script], {
    cwd: root,
    encoding: "utf8",
    env: { ...process.env, PDYN: bin },
  });
  // One JSON value per command: a result on one line, an error pretty-printed over several.
  const values = [];
  let buffer = "";
  for (const line of out.split("\n")) {
    buffer += `${line}\n`;
    try {
      values.push(JSON.parse(buffer));
      buffer = "";
    } catch (_) {
      // not complete yet
    }
  }
  assert.equal(buffer.trim(), "", "the shell's output ends with a whole JSON value");
  return values;
}

for (const ex of scripts) {
  test(`${ex}: the script runs in the page with the CLI's output, line by line`, async () => {
    const { page, errors } = await open(chromium.browser, server.url, `#example=${ex}`);
    assert.equal(await page.evaluate(() => document.body.dataset.mode), "script");
    assert.equal(await page.isDisabled("#derive"), true);
    const r = await command(page, "run");
    assert.ok(r?.value?.ok, `${ex}: failed: ${await page.textContent("#error")}`);
    assert.equal(r.cmd, "commands");
    const want = shellJson(ex);
    assert.equal(r.value.commands.length, want.length, `${ex}: number of commands`);
    r.value.commands.forEach((c, i) => {
      const s = compare(c.result, want[i]);
      assert.deepEqual(s.mismatches, [], `${ex} line ${c.line}: texts differ`);
      // Runs are bit for bit (above). These symbolic commands' values still differ from the
      // CLI's by an ulp or two in some places (docs/web.md, "How close"): within 1e-13.
      assert.ok(s.maxScaled <= 1e-13, `${ex} line ${c.line}: ${s.worst}`);
    });
    assert.ok((await page.locator("#view-equations .katex").count()) > 0, `${ex}: nothing typeset`);
    assert.deepEqual(errors, []);
    await page.close();
  });
}

test("a script's bad line is located at the word that caused it", async () => {
  const { page } = await open(chromium.browser, server.url, "#example=examples/kin/polar_example.sh");
  const script = '# two commands\npdyn kin --polar "r = t, theta = t^2" --at t=1\npdyn kin "[t, t^, 0]"\n';
  await page.evaluate((t) => (window.pdynEditor.text = t), script);
  await command(page, "run");
  const box = page.locator("#error");
  assert.equal(await box.isHidden(), false);
  assert.equal(Number(await box.getAttribute("data-line")), 3);
  // Column of the `,` after `t^` inside the quoted position: 10 + 1 + 5.
  const column = Number(await box.getAttribute("data-column"));
  assert.ok(column >= 14 && column <= 17, `column ${column}`);
  assert.match(await page.evaluate(() => document.querySelector(".cm-error-line")?.textContent), /t\^, 0/);
  await page.close();
});

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
