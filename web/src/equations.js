// `pdyn derive --json`'s equations typeset with KaTeX: the equations of motion, their
// solution for the unknowns (when it exists) and the matrix form's entries.
import katex from "katex";
import "katex/dist/katex.min.css";

export function tex(node, latex, display = true) {
  const el = document.createElement("div");
  el.className = "eq";
  try {
    katex.render(latex, el, { displayMode: display, throwOnError: true, output: "htmlAndMathml" });
  } catch (err) {
    // A formula KaTeX cannot typeset is shown as its LaTeX, not lost.
    el.textContent = latex;
    el.title = String(err.message || err);
  }
  node.appendChild(el);
}

export function heading(node, text) {
  const h = document.createElement("h3");
  h.textContent = text;
  node.appendChild(h);
}

export function showDerivation(node, d) {
  node.replaceChildren();
  const title = document.createElement("h2");
  title.textContent = `${d.model} — ${d.form} form`;
  node.appendChild(title);
  if (d.equations.length) heading(node, "Equations of motion");
  else {
    const p = document.createElement("p");
    p.textContent = "Every coordinate is prescribed: no equation of motion to integrate — the forces this motion needs are what Forces computes.";
    node.appendChild(p);
  }
  for (const q of d.equations) {
    if (q.label) {
      const p = document.createElement("p");
      p.className = "label";
      p.textContent = q.label;
      node.appendChild(p);
    }
    tex(node, `${q.lhs.latex} = ${q.rhs.latex}`);
  }
  if (d.solution) {
    heading(node, "Solved for the unknowns");
    for (const s of d.solution) tex(node, `${latexName(s.unknown)} = ${s.expr.latex}`);
  }
  // The kinematics of each particle (what Newton's law is written from).
  if (d.particles?.length) {
    heading(node, "Kinematics");
    const vec = (v) => `\\begin{bmatrix} ${v.map((c) => c.latex).join(" \\\\ ")} \\end{bmatrix}`;
    for (const p of d.particles) {
      const name = p.name.replace(/[^A-Za-z0-9]/g, "");
      tex(node, `\\mathbf{r}_{\\mathrm{${name}}} = ${vec(p.r)},\\quad \\mathbf{v}_{\\mathrm{${name}}} = ${vec(p.v)},\\quad \\mathbf{a}_{\\mathrm{${name}}} = ${vec(p.a)}`);
    }
  }
  if (d.notes?.length) {
    heading(node, "Notes");
    const ul = document.createElement("ul");
    for (const n of d.notes) {
      const li = document.createElement("li");
      li.textContent = n;
      ul.appendChild(li);
    }
    node.appendChild(ul);
  }
}

/** `x''` → `\ddot{x}`, `theta'` → `\dot{\theta}`, names with an index as subscripts. */
function latexName(name) {
  const m = /^([A-Za-z]+)(\d*)('*)$/.exec(name);
  if (!m) return `\\mathrm{${name.replace(/[_{}\\]/g, "")}}`;
  const greek = new Set(["alpha", "beta", "gamma", "delta", "theta", "phi", "psi", "omega", "lambda", "mu", "rho", "sigma", "tau"]);
  let base = greek.has(m[1]) ? `\\${m[1]}` : m[1].length > 1 ? `\\mathrm{${m[1]}}` : m[1];
  if (m[2]) base = `${base}_{${m[2]}}`;
  if (m[3] === "''") return `\\ddot{${base}}`;
  if (m[3] === "'") return `\\dot{${base}}`;
  return base;
}
