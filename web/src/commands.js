// A script of `pdyn kin` / `pdyn dsolve` lines, as the page ran it: each command line, then
// its results typeset with KaTeX from the LaTeX the CLI's `--json` carries (kinematic
// quantities and their values at instants; closed-form solutions case by case; the rules of
// straight-line motion).
import { tex, heading } from "./equations.js";

const vector = (v) => `\\begin{bmatrix} ${v.map((c) => c.latex).join(" \\\\ ")} \\end{bmatrix}`;
const latexOf = (q) => (Array.isArray(q) ? vector(q) : q.latex);
// Names the CLI prints (`a_polar`, `e_t`, `v`) as symbols.
function symbol(name) {
  const m = /^([A-Za-z]+)(?:_(\w+))?$/.exec(name);
  if (!m) return `\\mathrm{${name.replace(/[^A-Za-z0-9]/g, "")}}`;
  const base = ["v", "a", "r", "n", "e", "t", "u"].includes(m[1]) && !m[2] ? `\\mathbf{${m[1]}}` : m[1].length > 1 ? `\\mathrm{${m[1]}}` : m[1];
  const greek = ["theta", "phi", "psi", "omega", "alpha", "beta", "rho"];
  return m[2] ? `${base}_{${greek.includes(m[2]) ? `\\${m[2]}` : `\\mathrm{${m[2]}}`}}` : base;
}

function note(node, text, cls = "label") {
  const p = document.createElement("p");
  p.className = cls;
  p.textContent = text;
  node.appendChild(p);
}

function showKin(node, r) {
  for (const [name, q] of Object.entries(r.quantities)) tex(node, `${symbol(name)} = ${latexOf(q)}`);
  if (r.straight) note(node, "Straight-line motion: the normal is undefined (shown as 0) and R is infinite.");
  for (const at of r.at ?? []) {
    heading(node, `At ${at.resolved}`);
    for (const [name, v] of Object.entries(at.values)) {
      const approx = v.value ? ` \\approx ${v.value.length === 1 ? v.value[0].toPrecision(8) : `(${v.value.map((x) => x.toPrecision(8)).join(",\\ ")})`}` : "";
      tex(node, `${symbol(name)} = ${latexOf(v.exact)}${approx}`);
    }
    for (const [name, why] of Object.entries(at.undefined ?? {})) note(node, `${name}: undefined — ${why}`);
  }
  if (r.max) {
    const m = r.max;
    const val = typeof m.value === "number" ? m.value : m.value.latex;
    const where = typeof m.at === "number" ? m.at : m.at.latex;
    heading(node, `Maximum of ${m.expr}`);
    tex(node, `\\max = ${val} \\quad\\text{at}\\quad ${where}`);
  }
}

function showDsolve(node, r) {
  if (r.cases) {
    for (const c of r.cases) {
      if (c.condition) heading(node, `Case ${c.condition.expr.text} ${c.condition.relation} 0`);
      for (const [coord, s] of Object.entries(c.solution)) tex(node, `${coord}(t) = ${s.latex}`);
      if (c.roots.length) note(node, `characteristic roots: ${c.roots.join(", ")}`);
    }
    if (r.when) note(node, `when: t = ${r.when.t}`);
    return;
  }
  for (const q of r.quantities) {
    if (q.closed_form) tex(node, `${q.name} = ${q.closed_form.latex}`);
    else note(node, `${q.name}: numerical quadrature (no closed form used)`);
  }
}

/** A command's words as a shell line (words with blanks or shell characters quoted). */
export function commandLine(words) {
  return words.map((w) => (/[\s"'*()^$&|;<>]/.test(w) ? `'${w.replace(/'/g, `'"'"'`)}'` : w)).join(" ");
}

/** The commands of a script, typeset into `node`. */
export function showCommands(node, commands) {
  node.replaceChildren();
  for (const c of commands) {
    const h = document.createElement("h2");
    const code = document.createElement("code");
    code.textContent = commandLine(c.command);
    h.appendChild(code);
    node.appendChild(h);
    if (c.failed) note(node, `refused (the line ends in || true): ${c.text}`, "refused");
    else if (c.name === "kin") showKin(node, c.result);
    else showDsolve(node, c.result);
    if (c.result.assumed_positive?.length) note(node, `assuming ${c.result.assumed_positive.join(", ")} > 0`);
  }
}
