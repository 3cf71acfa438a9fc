//! `pdyn derive`'s output, for every front end: the equations of motion of a model as the
//! chapter writes them (text or LaTeX, within a print budget: [`super::bounded`]), or all of them as
//! JSON with text and LaTeX of each expression.

use super::bounded::{chars, Lines};
use crate::Error;
use pdyn_expr::budget::{PrintSize, PRINT_CHARS};
use pdyn_expr::{Id, Pool};
use pdyn_mech::derive::{Form, UnknownKind};
use pdyn_mech::matrix_form::{matrix_form, MatrixForm};
use pdyn_mech::{derive, DeriveOptions};
use serde_json::json;

/// What to derive and how to print it.
#[derive(Clone, Debug)]
pub struct DeriveRequest {
    /// Expressions in LaTeX (the text output).
    pub latex: bool,
    /// Everything as JSON (each expression as text and LaTeX) instead of text.
    pub json: bool,
    /// Which equations to build.
    pub form: Form,
    /// Largest system eliminated symbolically (larger ones are solved numerically when run).
    pub symbolic_limit: usize,
    /// Eliminate exactly even when expensive, and print explicit accelerations up to
    /// [`PRINT_CHARS`] (otherwise [`EXPLICIT_CHARS`], larger ones by reference).
    pub solve: bool,
}

/// Largest system eliminated symbolically unless asked otherwise (`--symbolic-limit`).
pub const SYMBOLIC_LIMIT: usize = 6;

impl Default for DeriveRequest {
    fn default() -> DeriveRequest {
        DeriveRequest {
            latex: false,
            json: false,
            form: Form::Auto,
            symbolic_limit: SYMBOLIC_LIMIT,
            solve: false,
        }
    }
}

/// Longest explicit acceleration (or reaction) `pdyn derive` prints without `--solve`, in
/// characters: larger ones are written by reference, `q1'' = (M⁻¹ f)_1`, with their size. A
/// double pendulum's explicit accelerations are 440 characters; the 3-link chain's, 1,600, are
/// printed on request (`--solve`), up to [`PRINT_CHARS`].
pub const EXPLICIT_CHARS: usize = 600;

/// Most coordinates whose equations `pdyn derive` writes out one by one. The derivation lays
/// out `A x = b` densely (n² entries) and prints every equation: at the 398-particle net's
/// 1,194 coordinates that is seconds, at the 10⁴-particle cloth's 29,994 it was 3.6 GB and
/// minutes for 105 MB of text nobody reads. Larger models are refused at once, saying what
/// to do instead.
pub const DERIVE_MAX_COORDINATES: usize = 3_000;

/// The derivation of `model` printed as `a` asks (what `pdyn derive MODEL` prints). A model
/// loaded with deferred families ([`pdyn_mech::model::load_deferring`]) is expanded here,
/// after the size check.
pub fn report(mut model: pdyn_mech::Model, a: &DeriveRequest) -> Result<String, Error> {
    let n = model.coordinates.len();
    if n > DERIVE_MAX_COORDINATES {
        return Err(Error::Derive {
            origin: model.origin.clone(),
            error: pdyn_mech::DeriveError::new(
                format!(
                    "this model has {n} coordinates ({} particles): `pdyn derive` writes out the \
                     equations of models of at most {DERIVE_MAX_COORDINATES} coordinates",
                    model.particles.len()
                ),
                "derive a smaller instance of the same families (a smaller index range, e.g. \
                 `n = 5` under [indices]) to read its equations; `pdyn run`, `pdyn modes` and \
                 `pdyn equilibrium` handle this size",
            ),
        });
    }
    model.expand_deferred().map_err(|error| Error::Derive {
        origin: model.origin.clone(),
        error,
    })?;
    // A model with contacts is printed in one mode of its contacts, named in a note.
    let mut hybrid_note = None;
    if pdyn_mech::hybrid::is_hybrid(&model) && !model.contacts.is_empty() {
        let (m, note) = pdyn_mech::hybrid::reference_model(&model);
        model = m;
        hybrid_note = Some(note);
    }
    let opts = DeriveOptions {
        form: a.form,
        symbolic_limit: a.symbolic_limit,
        solve_budget: if a.solve {
            pdyn_mech::derive::FULL_SOLVE_BUDGET
        } else {
            pdyn_mech::derive::PRINT_SOLVE_BUDGET
        },
        // The solution is printed, and only when it is short: simplifying it is worth the
        // solve budget's remainder, not more (the 3-link chain's cost more than the whole
        // `pdyn derive` of 4 or 8 links, to be printed by reference).
        simplify_solution_within_budget: true,
        ..DeriveOptions::default()
    };
    let mut d = derive(&mut model, &opts).map_err(|error| Error::Derive {
        origin: model.origin.clone(),
        error,
    })?;
    d.notes.extend(hybrid_note);
    // A closed form of accelerations too large to print is of no use to a reader, and
    // attempting it re-derives and formats huge coefficients (32 MB on the 4-link chain).
    let explicit_chars = if a.solve { PRINT_CHARS } else { EXPLICIT_CHARS };
    let solution_printable = d.solution.as_ref().is_some_and(|sol| {
        sol.iter().all(|&s| {
            model
                .pool
                .to_text_within(s, a.latex, explicit_chars)
                .is_ok()
        })
    });
    // An initial condition left to `pdyn forces` (`rate = "omega"`, an unknown) has no
    // number: a closed form from it is not attempted, and the reason is said below.
    let left_to_forces = model.unknown_initials.first().map(|u| {
        format!(
            "the {} of `{}` is `{}`, an unknown that `pdyn forces` solves for",
            if u.key == "rate" {
                "rate"
            } else {
                "initial value"
            },
            u.name,
            u.text
        )
    });
    let exact = if solution_printable && left_to_forces.is_none() {
        Some(crate::sim::exact::symbolic_closed_form(&mut model))
    } else {
        None
    };
    // The readable `M q'' = f` of the projected form (entries collected and factored).
    let matrix = if a.json || d.form == Form::Projected {
        matrix_form(&mut model.pool, &d)
    } else {
        None
    };
    let rendered = matrix
        .as_ref()
        .map(|m| Rendered::new(&mut model.pool, m, a.latex));
    if a.json {
        return Ok(format!("{}\n", to_json(&mut model, &d, matrix.as_ref())));
    }
    let p = &model.pool;
    let mut o = Lines::new(p, a.latex);
    o.line(&model.name);
    o.line("");
    o.line("Coordinates:");
    for (ci, c) in model.coordinates.iter().enumerate() {
        match &c.kind {
            pdyn_mech::model::CoordinateKind::Free { initial, rate } => {
                // An initial condition in [unknowns] has no number: show what was written.
                let shown = |key: &str, value: f64| match model.unknown_initial(ci, key) {
                    Some(u) => format!("{} (unknown, for pdyn forces)", u.text),
                    None => value.to_string(),
                };
                o.line(&format!(
                    "  {} (unknown): {0}(0) = {}, {0}'(0) = {}",
                    c.name,
                    shown("initial", *initial),
                    shown("rate", *rate)
                ))
            }
            pdyn_mech::model::CoordinateKind::Prescribed { expr } => {
                o.expr_in(&format!("  {} = ", c.name), &c.name, *expr, " (prescribed)");
            }
        }
    }
    o.line("");
    o.line("Particles:");
    for pk in &d.particles {
        o.expr_in(
            &format!("  {} (mass ", pk.name),
            &format!("mass of {}", pk.name),
            pk.mass,
            ")",
        );
        for (name, v) in [("r", pk.r), ("v", pk.v), ("a", pk.a), ("F", pk.force)] {
            o.vector("    ", name, v);
        }
    }
    match (&d.form, &matrix, &rendered) {
        (Form::Projected, Some(m), Some(r)) => matrix_section(&mut o, m, r),
        _ => {
            let title = match d.form {
                Form::Projected => "Equations of motion (projected on the coordinates, M q'' = f)",
                _ => "Equations of motion (F = ma, component by component)",
            };
            o.line("");
            o.line(&format!("{title}:"));
            for e in &d.equations {
                o.line(&format!("  {}:", e.label));
                equation(&mut o, &e.label, e.lhs, e.rhs);
            }
        }
    }
    for n in &d.notes {
        o.line(&format!("  note: {n}"));
    }
    if d.free.is_empty() {
        o.line("");
        o.line(
            "Every coordinate is prescribed: there are no equations of motion to solve. \
             The forces this motion needs are found by `pdyn forces`.",
        );
        return Ok(o.out);
    }
    let names: Vec<String> = d.unknowns.iter().map(|u| u.name.clone()).collect();
    o.line("");
    o.names("Unknowns: ", &names, ", ", "");
    // How an unknown is written when its explicit form is not printed.
    let by_reference = |k: usize| -> String {
        match (d.form, a.latex) {
            (Form::Projected, false) => format!("(M⁻¹ f)_{}", k + 1),
            (Form::Projected, true) => format!("\\left(M^{{-1}} f\\right)_{{{}}}", k + 1),
            (_, false) => format!("(A⁻¹ b)_{}", k + 1),
            (_, true) => format!("\\left(A^{{-1}} b\\right)_{{{}}}", k + 1),
        }
    };
    // The explicit form of each unknown when it is small, else `None`.
    let explicit: Vec<Option<String>> = match &d.solution {
        Some(sol) => sol
            .iter()
            .map(|&s| p.to_text_within(s, a.latex, explicit_chars).ok())
            .collect(),
        None => vec![None; d.unknowns.len()],
    };
    match &d.solution {
        Some(sol) => {
            o.line("");
            o.line("Solved:");
            for (k, (u, &s)) in d.unknowns.iter().zip(sol).enumerate() {
                match &explicit[k] {
                    Some(text) => o.line(&format!("  {} = {text}", u.name)),
                    None => {
                        let size = match p.to_text_within(s, a.latex, PRINT_CHARS) {
                            Ok(t) => PrintSize::Chars(chars(&t)),
                            Err(size) => size,
                        };
                        let hint = if a.solve {
                            format!("over the printing budget of {PRINT_CHARS}")
                        } else {
                            format!("over {EXPLICIT_CHARS}: `--solve` prints explicit forms up to {PRINT_CHARS}")
                        };
                        o.line(&format!(
                            "  {} = {}    (explicit form: {size}, {hint}; `--json` gives it whole)",
                            u.name,
                            by_reference(k)
                        ));
                    }
                }
            }
        }
        None => {
            let why = if d.system.cols() > a.symbolic_limit {
                format!("more than {} unknowns", a.symbolic_limit)
            } else if a.solve {
                "exact elimination is over its work budget".to_string()
            } else {
                "exact elimination is expensive here; --solve tries it".to_string()
            };
            let system = if d.form == Form::Projected {
                "M q'' = f"
            } else {
                "A x = b"
            };
            o.line("");
            o.line(&format!(
                "The {}×{} linear system {system} is solved numerically at each evaluation ({why}).",
                d.system.rows(),
                d.system.cols(),
            ));
        }
    }
    let state_names: Vec<String> = d.state_names.clone();
    o.line("");
    o.names("First-order system, w = [", &state_names, ", ", "]:");
    let n = d.free.len();
    for i in 0..n {
        o.line(&format!(
            "  d/dt {} = {}",
            d.state_names[i],
            d.state_names[n + i]
        ));
    }
    for (k, u) in d.unknowns.iter().enumerate() {
        if let UnknownKind::Acceleration(_) = u.kind {
            let rhs = explicit[k].clone().unwrap_or_else(|| by_reference(k));
            o.line(&format!(
                "  d/dt {}' = {rhs}",
                u.name.trim_end_matches('\'')
            ));
        }
    }
    if !d.recovered.is_empty() {
        o.line("");
        o.line("Reactions recovered from F = ma (the projected form eliminated them):");
        for (n, e) in &d.recovered {
            o.expr(&format!("  {n} = "), n, *e);
        }
    }
    match &exact {
        Some(Ok(ex)) => {
            o.line("");
            o.line("Closed-form solution (linear with constant coefficients):");
            for (k, case) in ex.closed.cases.iter().enumerate() {
                if let Some(c) = case.condition {
                    let rel = match c.relation {
                        pdyn_mech::dsolve::Relation::Positive => "> 0",
                        pdyn_mech::dsolve::Relation::Zero => "= 0",
                        pdyn_mech::dsolve::Relation::Negative => "< 0",
                    };
                    let chosen = if k == ex.case {
                        "  <- applies to the parameter values"
                    } else {
                        ""
                    };
                    let suffix = format!(" {rel}{chosen}");
                    o.expr_in("  case ", &format!("case {}", k + 1), c.expr, &suffix);
                }
                for (q, &s) in ex.closed.coords.iter().zip(&case.solution) {
                    let name = p.name(*q);
                    o.expr(&format!("  {name}(t) = "), &format!("{name}(t)"), s);
                }
            }
        }
        Some(Err(why)) => {
            let why = why.to_string();
            if chars(&why) + 20 <= PRINT_CHARS {
                o.line("");
                o.line(&format!("No closed form: {why}."));
            } else {
                // The reason names the equation and the symbol (`q1`), then quotes the
                // coefficient: keep what comes before the coefficient.
                let head = match why.match_indices('`').nth(1) {
                    Some((i, _)) => &why[..=i],
                    None => why.split('`').next().unwrap_or("").trim_end(),
                };
                o.line("");
                o.line(&format!(
                    "No closed form: {head} … ({} characters, over the printing budget of {PRINT_CHARS}).",
                    chars(&why)
                ));
            }
        }
        None if left_to_forces.is_some() && d.solution.is_some() => {
            o.line("");
            o.line(&format!(
                "No closed form attempted: {}.",
                left_to_forces.as_deref().unwrap_or_default()
            ));
        }
        None if d.solution.is_some() => {
            o.line("");
            o.line(&format!(
                "No closed form attempted: the explicit accelerations are over {explicit_chars} characters."
            ));
        }
        None => {}
    }
    let out = o.out;
    // The process ends after printing: freeing the pool's millions of nodes and memo tables
    // one by one was 5 % of `pdyn derive` on the 100-link chain, for memory the exit returns
    // anyway.
    std::mem::forget((model, d, matrix, rendered, exact));
    Ok(out)
}

/// `lhs = rhs` under its label: on one line when it fits, else the two sides on two lines,
/// each within the budget.
fn equation(o: &mut Lines, label: &str, lhs: Id, rhs: Id) {
    let l = o.pool.to_text_within(lhs, o.latex, PRINT_CHARS);
    let r = o.pool.to_text_within(rhs, o.latex, PRINT_CHARS);
    if let (Ok(l), Ok(r)) = (&l, &r) {
        if chars(l) + chars(r) + 7 <= PRINT_CHARS {
            o.line(&format!("    {l} = {r}"));
            return;
        }
    }
    o.expr("    ", &format!("left side of `{label}`"), lhs);
    o.expr("      = ", &format!("right side of `{label}`"), rhs);
}

/// The entries of `M` and `f` rendered once (collected sums print through `&mut Pool`).
struct Rendered {
    /// `M[j,k]`, row-major, whole.
    mass: Vec<String>,
    /// `f[j]`, whole.
    forcing: Vec<String>,
}

impl Rendered {
    fn new(p: &mut Pool, m: &MatrixForm, latex: bool) -> Rendered {
        // An entry too large to collect is over the budget: its size is what prints.
        let memo = pdyn_expr::print::TextMemo::default();
        let show = |p: &mut Pool, e: &pdyn_mech::matrix_form::Entry| match &e.collected {
            Some(_) if latex => e.render(p, latex),
            Some(_) => e.render_text_memo(p, &memo),
            None => String::new(),
        };
        // A symmetric M's lower triangle is the upper one's text (half the formatting: at
        // n = 100 the entries are 1.7 MB of text).
        let n = m.n;
        let mut mass: Vec<String> = Vec::with_capacity(n * n);
        for j in 0..n {
            for k in 0..n {
                let s = if m.symmetric && k < j {
                    mass[k * n + j].clone()
                } else {
                    show(p, &m.mass[j * n + k])
                };
                mass.push(s);
            }
        }
        Rendered {
            mass,
            forcing: m.forcing.iter().map(|e| show(p, e)).collect(),
        }
    }
}

/// The projected equations as `M(q) q'' = f(q, q', t)`: in text one entry per line (the
/// upper triangle of a symmetric `M`, zeros left out); in LaTeX the matrices, with entries
/// inline when every row fits on its line and by name (`M_{1,2}`, listed below) otherwise.
fn matrix_section(o: &mut Lines, m: &MatrixForm, r: &Rendered) {
    let n = m.n;
    let p = o.pool;
    let entry =
        |o: &mut Lines, prefix: &str, what: &str, e: &pdyn_mech::matrix_form::Entry, s: &str| {
            if e.collected.is_some() {
                o.rendered(prefix, what, s);
            } else {
                o.expr(prefix, what, e.expr);
            }
        };
    let listed = |j: usize, k: usize| -> bool {
        m.mass[j * n + k].expr != Pool::ZERO && !(m.symmetric && k < j)
    };
    type Name<'n> = Option<&'n dyn Fn(usize, usize) -> String>;
    // `name = entry` lines for M's listed entries and for f, named (1-based) by `mass_name`
    // and `f_name` (`None`: not listed).
    let list = |o: &mut Lines, mass_name: Name, f_name: Option<&dyn Fn(usize) -> String>| {
        if let Some(name) = mass_name {
            for j in 0..n {
                for k in (0..n).filter(|&k| listed(j, k)) {
                    let name = name(j + 1, k + 1);
                    let i = j * n + k;
                    entry(o, &format!("  {name} = "), &name, &m.mass[i], &r.mass[i]);
                }
            }
        }
        if let Some(name) = f_name {
            for j in 0..n {
                let name = name(j + 1);
                entry(
                    o,
                    &format!("  {name} = "),
                    &name,
                    &m.forcing[j],
                    &r.forcing[j],
                );
            }
        }
    };
    o.line("");
    o.line("Equations of motion (projected on the coordinates), M(q) q'' = f(q, q', t):");
    let accs: Vec<String> = m
        .accelerations
        .iter()
        .map(|&q| if o.latex { p.to_latex(q) } else { p.to_text(q) })
        .collect();
    if !o.latex {
        o.names("  q'' = [", &accs, ", ", "]");
        let mut what = Vec::new();
        if m.symmetric && n > 1 {
            what.push("M is symmetric: M[j,k] is listed for j ≤ k");
        }
        if (0..n * n).any(|i| m.mass[i].expr == Pool::ZERO) {
            what.push("entries not listed are 0");
        }
        if !what.is_empty() {
            o.line(&format!("  ({})", what.join("; ")));
        }
        list(
            o,
            Some(&|j, k| format!("M[{j},{k}]")),
            Some(&|j| format!("f[{j}]")),
        );
        return;
    }
    // LaTeX: entries inline when every row fits on its line.
    let fits = |s: &str, e: &pdyn_mech::matrix_form::Entry| {
        e.collected.is_some() && chars(s) <= PRINT_CHARS / (n + 1)
    };
    let m_inline = (0..n * n).all(|i| fits(&r.mass[i], &m.mass[i]));
    let f_inline = (0..n)
        .all(|j| fits(&r.forcing[j], &m.forcing[j]) && chars(&r.forcing[j]) + 8 <= PRINT_CHARS);
    o.line("  \\begin{bmatrix}");
    for j in 0..n {
        let row: Vec<String> = (0..n)
            .map(|k| {
                if m_inline {
                    r.mass[j * n + k].clone()
                } else if m.mass[j * n + k].expr == Pool::ZERO {
                    "0".into()
                } else {
                    let (a, b) = if m.symmetric {
                        (j.min(k), j.max(k))
                    } else {
                        (j, k)
                    };
                    format!("M_{{{},{}}}", a + 1, b + 1)
                }
            })
            .collect();
        let end = if j + 1 < n { " \\\\" } else { "" };
        o.line(&format!("    {}{end}", row.join(" & ")));
    }
    o.line("  \\end{bmatrix}");
    o.line("  \\begin{bmatrix}");
    for (j, q) in accs.iter().enumerate() {
        let end = if j + 1 < n { " \\\\" } else { "" };
        o.line(&format!("    {q}{end}"));
    }
    o.line("  \\end{bmatrix}");
    o.line("  =");
    o.line("  \\begin{bmatrix}");
    for j in 0..n {
        let end = if j + 1 < n { " \\\\" } else { "" };
        let e = if f_inline {
            r.forcing[j].clone()
        } else {
            format!("f_{{{}}}", j + 1)
        };
        o.line(&format!("    {e}{end}"));
    }
    o.line("  \\end{bmatrix}");
    if !m_inline && m.symmetric && n > 1 {
        o.line("  % M is symmetric: M_{j,k} is listed for j \\le k");
    }
    list(
        o,
        (!m_inline).then_some(&|j, k| format!("M_{{{j},{k}}}")),
        (!f_inline).then_some(&|j| format!("f_{{{j}}}")),
    );
}

fn to_json(
    model: &mut pdyn_mech::Model,
    d: &pdyn_mech::Derivation,
    matrix: Option<&MatrixForm>,
) -> serde_json::Value {
    // `mass_matrix` (n × n, row-major rows, both triangles) and `forcing`: the entries
    // collected and factored as the text prints them (equal to the derivation's).
    let (mass, forcing) = match matrix {
        Some(m) => {
            let p = &mut model.pool;
            let mut entry = |e: &pdyn_mech::matrix_form::Entry| json!({"text": e.render(p, false), "latex": e.render(p, true)});
            let mass: Vec<Vec<serde_json::Value>> = (0..m.n)
                .map(|j| (0..m.n).map(|k| entry(&m.mass[j * m.n + k])).collect())
                .collect();
            let forcing: Vec<serde_json::Value> = m.forcing.iter().map(&mut entry).collect();
            (json!(mass), json!(forcing))
        }
        None => (serde_json::Value::Null, serde_json::Value::Null),
    };
    let p = &model.pool;
    let e = |id: Id| json!({"text": p.to_text(id), "latex": p.to_latex(id)});
    let v = |x: [Id; 3]| json!(x.iter().map(|&c| e(c)).collect::<Vec<_>>());
    json!({
        "model": model.name,
        "form": format!("{:?}", d.form).to_lowercase(),
        "coordinates": model.coordinates.iter().enumerate().map(|(ci, c)| match &c.kind {
            // An initial value or rate in [unknowns] is null, with what was written beside it.
            pdyn_mech::model::CoordinateKind::Free { initial, rate }
                if model.unknown_initials.iter().any(|u| u.coordinate == ci) =>
            {
                let written = model
                    .unknown_initials
                    .iter()
                    .filter(|u| u.coordinate == ci)
                    .map(|u| (u.key.to_string(), json!(u.text)))
                    .collect::<serde_json::Map<_, _>>();
                json!({"name": c.name, "kind": "unknown", "initial": initial, "rate": rate, "in_unknowns": written})
            }
            pdyn_mech::model::CoordinateKind::Free { initial, rate } =>
                json!({"name": c.name, "kind": "unknown", "initial": initial, "rate": rate}),
            pdyn_mech::model::CoordinateKind::Prescribed { expr } =>
                json!({"name": c.name, "kind": "prescribed", "expr": e(*expr)}),
        }).collect::<Vec<_>>(),
        "particles": d.particles.iter().map(|pk| json!({
            "name": pk.name, "mass": e(pk.mass), "r": v(pk.r), "v": v(pk.v), "a": v(pk.a), "force": v(pk.force),
        })).collect::<Vec<_>>(),
        "equations": d.equations.iter().map(|q| json!({"label": q.label, "lhs": e(q.lhs), "rhs": e(q.rhs)})).collect::<Vec<_>>(),
        "unknowns": d.unknowns.iter().map(|u| u.name.clone()).collect::<Vec<_>>(),
        "solution": d.solution.as_ref().map(|s| d.unknowns.iter().zip(s).map(|(u, &x)| json!({"unknown": u.name, "expr": e(x)})).collect::<Vec<_>>()),
        "state": d.state_names,
        "notes": d.notes,
        "mass_matrix": mass,
        "forcing": forcing,
    })
}
