// The playground's page: the model editor, the commands (run, derive, check, forces, sweep)
// sent to the engine's worker, and the results: warnings first, then the views. A script of
// `pdyn kin` / `pdyn dsolve` lines (examples/kin, examples/dsolve) runs line by line instead.
import "./style.css";
import { createEditor } from "./editor.js";
import { Engine } from "./engine.js";
import { showPlots } from "./plots.js";
import { showDerivation } from "./equations.js";
import { showCommands, commandLine } from "./commands.js";
import { Scene } from "./scene.js";
import { encodeModel, readHash } from "./share.js";

// Every model file of examples/, and the kin/dsolve scripts, bundled as text (~45 kB); not
// examples/large/ (thousands of particles: their derivation does not fit a browser tab).
const files = import.meta.glob(["../../examples/**/*.toml", "!../../examples/large/**", "../../examples/kin/*.sh", "../../examples/dsolve/*.sh"], { query: "?raw", import: "default", eager: true });
const EXAMPLES = Object.fromEntries(
  Object.entries(files)
    .map(([path, text]) => [path.replace("../../", ""), text])
    .sort(([a], [b]) => a.localeCompare(b)),
);
const DEFAULT_EXAMPLE = "examples/satellite.toml";
// Small sizes by default in the browser, where the CLI's defaults are benchmark sizes
// (32,000 and 6,912 atoms): 500 LJ atoms. The option box shows it and can be cleared.
const BROWSER_SET = { "examples/md/lj_liquid.toml": "n=5", "examples/md/lj_formula.toml": "n=5" };

const $ = (id) => document.getElementById(id);
const state = { origin: DEFAULT_EXAMPLE, lastRun: null };

const editor = createEditor($("editor"), () => {
  $("error").hidden = true;
  state.origin = state.origin.startsWith("examples/") && !state.origin.endsWith(" (edited)") ? `${state.origin} (edited)` : state.origin;
  updateMode();
});

// A script's first line that is not blank or a comment starts with `pdyn` (as
// pdyn-web's `script::is_script`); anything else is a model file.
function isScript(text) {
  const first = text.split("\n").map((l) => l.trim()).find((l) => l && !l.startsWith("#"));
  return first === "pdyn" || (first ?? "").startsWith("pdyn ");
}

// Scripts run with Run; the model commands and run options do not apply to them.
function updateMode() {
  const script = isScript(editor.text);
  editor.language = script ? "shell" : "toml";
  for (const id of ["derive", "check", "forces", "sweep"]) $(id).disabled = script;
  $("options").disabled = script;
  $("run").title = script ? "Run the script's pdyn kin / pdyn dsolve lines (Ctrl+Enter)" : "Run the model (Ctrl+Enter)";
  document.body.dataset.mode = script ? "script" : "model";
}
const engine = new Engine((version) => {
  $("engine-status").textContent = `engine ready (pdyn ${version}, WebAssembly)`;
  document.body.dataset.ready = "true";
});
// For the browser tests and the console: the engine as the page uses it.
window.pdynEngine = engine;
window.pdynEditor = editor;
const scene = new Scene($("scene"), $("frame"), $("frame-time"), $("play"));

// ----- examples and the URL
function fillExamples() {
  const select = $("example");
  const groups = {};
  for (const path of Object.keys(EXAMPLES)) {
    const dir = path.split("/").slice(0, -1).join("/");
    (groups[dir] ??= []).push(path);
  }
  for (const [dir, paths] of Object.entries(groups)) {
    const g = document.createElement("optgroup");
    g.label = dir;
    for (const p of paths) {
      const o = document.createElement("option");
      o.value = p;
      o.textContent = p.split("/").pop();
      g.appendChild(o);
    }
    select.appendChild(g);
  }
  select.addEventListener("change", () => loadExample(select.value, true));
}

function loadExample(path, updateUrl) {
  if (!(path in EXAMPLES)) return false;
  editor.text = EXAMPLES[path];
  state.origin = path;
  updateMode();
  $("opt-set").value = BROWSER_SET[path] ?? "";
  $("example").value = path;
  if (updateUrl) history.replaceState(null, "", `#example=${encodeURIComponent(path)}`);
  return true;
}

async function shareLink() {
  const code = await encodeModel(editor.text);
  const url = `${location.origin}${location.pathname}#model=${code}`;
  history.replaceState(null, "", `#model=${code}`);
  try {
    await navigator.clipboard.writeText(url);
    setStatus("link copied");
  } catch (_) {
    setStatus("link in the address bar");
  }
}

// ----- options
function parsePairs(text, what) {
  const out = {};
  for (const part of text.split(",").map((s) => s.trim()).filter(Boolean)) {
    const m = /^([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(.+)$/.exec(part);
    const v = m ? Number(m[2]) : NaN;
    if (!m || !Number.isFinite(v)) throw new Error(`${what}: \`${part}\` is not name=number`);
    out[m[1]] = v;
  }
  return out;
}

function options(cmd) {
  const o = {};
  const num = (key) => {
    const v = $(`opt-${key}`).value.trim();
    if (v !== "") o[key] = Number(v);
  };
  for (const key of ["t_end", "rtol", "atol"]) num(key);
  const points = $("opt-points").value.trim();
  if (points !== "") o.points = Math.round(Number(points));
  const method = $("opt-method").value;
  if (method) o.method = method;
  const set = parsePairs($("opt-set").value, "set");
  if (Object.keys(set).length) o.set = set;
  if (cmd === "forces") {
    o.at = parsePairs($("opt-at").value, "forces at");
    for (const k of ["t_end", "rtol", "atol", "points", "method"]) delete o[k];
  }
  if (cmd === "derive") return { json: true, ...(o.set ? { set: o.set } : {}) };
  if (cmd === "check" || cmd === "sweep") o.json = false;
  // An MD run's atoms drawn every 20 steps (at most 200 frames kept).
  if (cmd === "run" && /^\[md\]/m.test(editor.text)) Object.assign(o, { frame_every: 20, max_frames: 200 });
  return o;
}

function cliEquivalent(cmd, o) {
  if (cmd === "commands") return state.origin.startsWith("examples/") && !state.origin.endsWith(" (edited)") ? `sh ${state.origin}` : "the script's lines, in a shell";
  const parts = [`pdyn ${cmd}`, state.origin.replace(" (edited)", "")];
  for (const [k, v] of Object.entries(o)) {
    if (k === "json" || k === "max_frames" || k === "frame_every") continue;
    const flag = `--${k.replace(/_/g, "-")}`;
    if (k === "set" || k === "at") parts.push(`${flag} ${Object.entries(v).map(([a, b]) => `${a}=${b}`).join(",")}`);
    else parts.push(`${flag} ${v}`);
  }
  if (cmd !== "derive" && cmd !== "forces") parts.push("--no-jit");
  return parts.join(" ");
}

// ----- results
function setStatus(text) {
  $("status").textContent = text;
}

function showWarnings(list) {
  const w = $("warnings");
  w.replaceChildren();
  w.hidden = !list.length;
  for (const text of list) {
    const p = document.createElement("p");
    p.textContent = `⚠ ${text}`;
    w.appendChild(p);
  }
}

function showError(value) {
  const e = value.error ?? {};
  const box = $("error");
  box.hidden = false;
  const loc = e.location;
  box.textContent = value.text || e.message || "failed";
  if (loc && loc.line) {
    box.dataset.line = loc.line;
    box.dataset.column = loc.column;
    editor.markError(loc.line, loc.column);
  } else {
    delete box.dataset.line;
  }
}

function selectTab(name) {
  for (const tab of document.querySelectorAll('[role="tab"]')) {
    const on = tab.id === `tab-${name}`;
    tab.setAttribute("aria-selected", String(on));
    tab.tabIndex = on ? 0 : -1;
    $(tab.getAttribute("aria-controls")).hidden = !on;
  }
}

function setupTabs() {
  const tabs = [...document.querySelectorAll('[role="tab"]')];
  tabs.forEach((tab, i) => {
    tab.addEventListener("click", () => selectTab(tab.id.slice(4)));
    tab.addEventListener("keydown", (e) => {
      const d = e.key === "ArrowRight" ? 1 : e.key === "ArrowLeft" ? -1 : 0;
      if (!d) return;
      const next = tabs[(i + d + tabs.length) % tabs.length];
      next.focus();
      selectTab(next.id.slice(4));
    });
  });
  selectTab("plots");
}

async function command(cmd) {
  if (cmd === "run" && isScript(editor.text)) cmd = "commands";
  else if (cmd !== "run" && isScript(editor.text)) return;
  let o;
  try {
    o = cmd === "commands" ? {} : options(cmd);
  } catch (err) {
    showError({ text: err.message });
    return;
  }
  $("error").hidden = true;
  editor.clearError();
  $("cli-equivalent").textContent = cliEquivalent(cmd, o);
  const bar = $("progress");
  bar.hidden = false;
  bar.removeAttribute("value");
  $("cancel").disabled = false;
  document.body.dataset.busy = "true";
  setStatus(`${cmd}…`);
  const t0 = performance.now();
  const { value, ms } = await engine.call(cmd, editor.text, state.origin, o, (done, all) => {
    bar.max = all || 1;
    bar.value = done;
  });
  const total = performance.now() - t0;
  bar.hidden = true;
  $("cancel").disabled = true;
  delete document.body.dataset.busy;
  if (value.cancelled) {
    setStatus("cancelled");
    return;
  }
  if (!value.ok) {
    showError(value);
    setStatus(`${cmd} failed`);
    return;
  }
  render(cmd, value);
  setStatus(`${cmd} done in ${total.toFixed(0)} ms (engine ${ms.toFixed(0)} ms)`);
  document.body.dataset.lastCommand = cmd;
  document.body.dataset.lastMs = String(total);
}

function render(cmd, value) {
  window.pdynLast = { cmd, value };
  if (cmd === "run") {
    state.lastRun = value;
    showWarnings(value.warnings ?? []);
    if (value.failure) showError({ text: value.failure.message, error: value.failure });
    $("text").textContent = value.report;
    showPlots($("view-plots"), value);
    scene.load(value);
    selectTab("plots");
  } else if (cmd === "commands") {
    showWarnings([]);
    showCommands($("view-equations"), value.commands);
    $("text").textContent = value.commands.map((c) => `$ ${commandLine(c.command)}\n${c.text}`).join("\n");
    selectTab("equations");
  } else if (cmd === "derive") {
    showWarnings([]);
    showDerivation($("view-equations"), value.derivation);
    $("text").textContent = JSON.stringify(value.derivation, null, 2);
    selectTab("equations");
  } else {
    showWarnings(value.warnings ?? []);
    if (value.failure) showError({ text: value.failure.message, error: value.failure });
    $("text").textContent = value.text ?? JSON.stringify(value.result, null, 2);
    selectTab("text");
  }
}

// ----- start
async function init() {
  fillExamples();
  setupTabs();
  for (const cmd of ["run", "derive", "check", "forces", "sweep"]) $(cmd).addEventListener("click", () => command(cmd));
  $("cancel").addEventListener("click", () => engine.cancel());
  $("share").addEventListener("click", shareLink);
  document.addEventListener("keydown", (e) => {
    if ((e.ctrlKey || e.metaKey) && e.key === "Enter") {
      e.preventDefault();
      command("run");
    }
    if (e.key === "Escape") engine.cancel();
  });
  const fromUrl = await readHash(location.hash);
  if (fromUrl.model !== undefined) {
    editor.text = fromUrl.model;
    state.origin = "model from the link";
  } else if (!(fromUrl.example && loadExample(fromUrl.example, false))) {
    loadExample(DEFAULT_EXAMPLE, false);
  }
  if (fromUrl.error) showError({ text: fromUrl.error });
  document.body.dataset.loaded = "true";
}

init();
