//! `pdyn derive MODEL`: the equations of motion of a model file, as the chapter writes them.

use super::load_model;
use clap::{Args, ValueEnum};
use pdyn::Error;
use pdyn_expr::{Id, Pool};
use pdyn_mech::derive::{Form, UnknownKind};
use pdyn_mech::{derive, DeriveOptions};
use serde_json::json;
use std::path::PathBuf;

/// Which equations to derive.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormArg {
    /// Newton's equations, or the projected form when undeclared reactions make them outnumber the unknowns.
    Auto,
    /// F = ma per particle with reactions as unknowns.
    Newton,
    /// M(q) q'' = f (Kane): workless reactions eliminated.
    Projected,
}

/// `pdyn derive`.
#[derive(Args, Debug)]
pub struct DeriveArgs {
    /// The model file (TOML), e.g. examples/satellite.toml.
    model: PathBuf,
    /// Print expressions in LaTeX.
    #[arg(long)]
    latex: bool,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
    /// Which equations to build.
    #[arg(long, value_enum, default_value_t = FormArg::Auto)]
    form: FormArg,
    /// Largest system eliminated symbolically (larger ones are solved numerically when run).
    #[arg(long, default_value_t = 6)]
    symbolic_limit: usize,
    /// Eliminate exactly even when it is expensive (explicit accelerations of a 3-link chain
    /// print as lines of 1,600 characters; without this flag such systems are printed as
    /// M q'' = f and solved numerically when run).
    #[arg(long)]
    solve: bool,
}

/// `pdyn derive MODEL`.
pub fn run(a: DeriveArgs) -> Result<String, Error> {
    let mut model = load_model(&a.model)?;
    let opts = DeriveOptions {
        form: match a.form {
            FormArg::Auto => Form::Auto,
            FormArg::Newton => Form::Newton,
            FormArg::Projected => Form::Projected,
        },
        symbolic_limit: a.symbolic_limit,
        solve_budget: if a.solve {
            pdyn_mech::derive::FULL_SOLVE_BUDGET
        } else {
            pdyn_mech::derive::CHEAP_SOLVE_BUDGET
        },
        ..DeriveOptions::default()
    };
    let d = derive(&mut model, &opts).map_err(|error| Error::Derive {
        origin: model.origin.clone(),
        error,
    })?;
    // A closed form of accelerations too large to print is of no use to a reader, and
    // attempting it re-derives and formats huge coefficients (32 MB on the 4-link chain).
    let solution_printable = d
        .solution
        .as_ref()
        .is_some_and(|sol| sol.iter().all(|&s| printable(&model.pool, s, a.latex)));
    let exact = if solution_printable {
        Some(pdyn::sim::exact::closed_form(&mut model))
    } else {
        None
    };
    let p = &model.pool;
    let show = |id: Id| -> String { bounded(p, id, a.latex) };
    let vec3 = |v: [Id; 3]| -> String {
        let parts: Vec<String> = v.iter().map(|&c| show(c)).collect();
        if a.latex {
            format!(
                "\\begin{{bmatrix}} {} \\end{{bmatrix}}",
                parts.join(" \\\\ ")
            )
        } else {
            format!("[{}]", parts.join(", "))
        }
    };
    if a.json {
        return Ok(format!("{}\n", to_json(&model, &d, p)));
    }
    let mut out = format!("{}\n\n", model.name);
    out += "Coordinates:\n";
    for c in &model.coordinates {
        match &c.kind {
            pdyn_mech::model::CoordinateKind::Free { initial, rate } => {
                out += &format!(
                    "  {} (unknown): {0}(0) = {initial}, {0}'(0) = {rate}\n",
                    c.name
                )
            }
            pdyn_mech::model::CoordinateKind::Prescribed { expr } => {
                out += &format!("  {} = {} (prescribed)\n", c.name, show(*expr))
            }
        }
    }
    out += "\nParticles:\n";
    for pk in &d.particles {
        out += &format!("  {} (mass {})\n", pk.name, show(pk.mass));
        out += &format!("    r = {}\n", vec3(pk.r));
        out += &format!("    v = {}\n", vec3(pk.v));
        out += &format!("    a = {}\n", vec3(pk.a));
        out += &format!("    F = {}\n", vec3(pk.force));
    }
    let title = match d.form {
        Form::Projected => "Equations of motion (projected on the coordinates, M q'' = f)",
        _ => "Equations of motion (F = ma, component by component)",
    };
    out += &format!("\n{title}:\n");
    for e in &d.equations {
        out += &format!("  {}:\n    {} = {}\n", e.label, show(e.lhs), show(e.rhs));
    }
    for n in &d.notes {
        out += &format!("  note: {n}\n");
    }
    if d.free.is_empty() {
        out += "\nEvery coordinate is prescribed: there are no equations of motion to solve. \
                The forces this motion needs are found by `pdyn forces`.\n";
        return Ok(out);
    }
    let names: Vec<&str> = d.unknowns.iter().map(|u| u.name.as_str()).collect();
    out += &format!("\nUnknowns: {}\n", names.join(", "));
    match &d.solution {
        Some(sol) => {
            out += "\nSolved:\n";
            for (u, &s) in d.unknowns.iter().zip(sol) {
                out += &format!("  {} = {}\n", u.name, show(s));
            }
            out += &format!(
                "\nFirst-order system, w = [{}]:\n",
                d.state_names.join(", ")
            );
            let n = d.free.len();
            for i in 0..n {
                out += &format!("  d/dt {} = {}\n", d.state_names[i], d.state_names[n + i]);
            }
            for (u, &s) in d.unknowns.iter().zip(sol) {
                if let UnknownKind::Acceleration(_) = u.kind {
                    out += &format!("  d/dt {}' = {}\n", u.name.trim_end_matches('\''), show(s));
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
            out += &format!(
                "\nThe {}×{} linear system A x = b is solved numerically at each evaluation \
                 ({why}).\n",
                d.system.rows(),
                d.system.cols(),
            );
        }
    }
    if !d.recovered.is_empty() {
        out += "\nReactions recovered from F = ma (the projected form eliminated them):\n";
        for (n, e) in &d.recovered {
            out += &format!("  {n} = {}\n", show(*e));
        }
    }
    match &exact {
        Some(Ok(ex)) => {
            out += "\nClosed-form solution (linear with constant coefficients):\n";
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
                    out +=
                        &format!("  case {} ≠ {}{chosen}\n", show(c.expr), rel).replace(" ≠ ", " ");
                }
                for (q, &s) in ex.closed.coords.iter().zip(&case.solution) {
                    out += &format!("  {}(t) = {}\n", p.name(*q), show(s));
                }
            }
        }
        Some(Err(why)) => {
            let why = why.to_string();
            if why.len() <= PRINT_CHARS {
                out += &format!("\nNo closed form: {why}.\n");
            } else {
                // The reason names the equation and the symbol (`q1`), then quotes the
                // coefficient: keep what comes before the coefficient.
                let head = match why.match_indices('`').nth(1) {
                    Some((i, _)) => &why[..=i],
                    None => why.split('`').next().unwrap_or("").trim_end(),
                };
                out += &format!(
                    "\nNo closed form: {head} … ({} characters, over the printing budget of {PRINT_CHARS}).\n",
                    why.len()
                );
            }
        }
        None if d.solution.is_some() => {
            out += "\nNo closed form attempted: the solved accelerations are over the printing budget.\n";
        }
        None => {}
    }
    Ok(out)
}

/// Longest expression `pdyn derive` prints, in characters (documented in docs/benchmarks.md):
/// past it the line names what is omitted and its size instead (`--json` has every expression
/// whole).
pub const PRINT_CHARS: usize = 2000;
/// Expressions larger than this many tree nodes are not even formatted (formatting the 4-link
/// chain's solution took seconds); any expression within [`PRINT_CHARS`] is far smaller.
const PRINT_NODES: usize = 4000;

/// Whether `id` prints within the budget.
fn printable(p: &Pool, id: Id, latex: bool) -> bool {
    p.tree_size(id, PRINT_NODES + 1) <= PRINT_NODES && render(p, id, latex).len() <= PRINT_CHARS
}

fn render(p: &Pool, id: Id, latex: bool) -> String {
    if latex {
        p.to_latex(id)
    } else {
        p.to_text(id)
    }
}

/// `id` as text or LaTeX, or a note with its size when it is over the budget.
fn bounded(p: &Pool, id: Id, latex: bool) -> String {
    if p.tree_size(id, PRINT_NODES + 1) > PRINT_NODES {
        return format!(
            "⟨not printed: over {PRINT_NODES} expression nodes; `pdyn derive --json` gives it whole⟩"
        );
    }
    let text = render(p, id, latex);
    if text.len() > PRINT_CHARS {
        format!(
            "⟨not printed: {} characters, over the budget of {PRINT_CHARS}; `pdyn derive --json` gives it whole⟩",
            text.len()
        )
    } else {
        text
    }
}

fn to_json(model: &pdyn_mech::Model, d: &pdyn_mech::Derivation, p: &Pool) -> serde_json::Value {
    let e = |id: Id| json!({"text": p.to_text(id), "latex": p.to_latex(id)});
    let v = |x: [Id; 3]| json!(x.iter().map(|&c| e(c)).collect::<Vec<_>>());
    json!({
        "model": model.name,
        "form": format!("{:?}", d.form).to_lowercase(),
        "coordinates": model.coordinates.iter().map(|c| match &c.kind {
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
    })
}
