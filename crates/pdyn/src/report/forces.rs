//! `pdyn forces`'s output, for every front end: the forces a prescribed motion requires, and
//! design criteria, as text (or LaTeX) or JSON.

use crate::output::json_num;
use crate::Error;
use pdyn_expr::{Id, Program};
use pdyn_mech::prescribed::{solve_forces, ForcesOptions};
use serde_json::json;

/// What to compute and how to print it.
#[derive(Clone, Debug, Default)]
pub struct ForcesRequest {
    /// The instant: `t` and coordinate values.
    pub at: Vec<(String, f64)>,
    /// Expressions in LaTeX (the text output).
    pub latex: bool,
    /// JSON instead of text.
    pub json: bool,
}

/// The forces of `model`'s prescribed motion at the instant `a.at`, printed as `a` asks (what
/// `pdyn forces MODEL` prints); `model` has its parameter values set.
pub fn report(mut model: pdyn_mech::Model, a: &ForcesRequest) -> Result<String, Error> {
    let opts = ForcesOptions { at: a.at.clone() };
    let res = solve_forces(&mut model, &opts).map_err(|error| Error::Forces {
        origin: model.origin.clone(),
        error,
    })?;
    // Monitors evaluated with the solution: derived quantities such as a load factor.
    let mut derived: Vec<(String, Option<Id>, Vec<f64>)> = Vec::new();
    if !model.run.monitors.is_empty() {
        let unk_ids: Vec<Id> = model
            .reactions
            .iter()
            .map(|r| r.id)
            .chain(model.unknowns.iter().map(|u| u.id))
            .collect();
        let mut leaves: Vec<Id> = model.parameters.iter().map(|p| p.id).collect();
        leaves.extend(&unk_ids);
        let pool = &mut model.pool;
        let t = pool.time();
        leaves.push(t);
        for m in &model.run.monitors {
            let sym = res.symbolic.as_ref().map(|sol| {
                let map = unk_ids.iter().copied().zip(sol.iter().copied()).collect();
                let e = pool.subs(m.expr, &map);
                pool.simplify(e)
            });
            let mut values = Vec::new();
            if let Ok(prog) = Program::compile(pool, &leaves, &[m.expr]) {
                let mut ws = prog.workspace();
                for sol in &res.numeric {
                    let mut input: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
                    input.extend(sol.iter().take(unk_ids.len()));
                    input.push(res.instant[0].1);
                    let mut out = [0.0];
                    prog.eval(&input, &mut ws, &mut out);
                    values.push(out[0]);
                }
            }
            derived.push((m.name.clone(), sym, values));
        }
    }
    let p = &model.pool;
    let show = |id: Id| {
        if a.latex {
            p.to_latex(id)
        } else {
            p.to_text(id)
        }
    };
    if a.json {
        let e = |id: Id| json!({"text": p.to_text(id), "latex": p.to_latex(id)});
        let v = json!({
            "model": model.name,
            "instant": res.instant.iter().map(|(n, v)| (n.clone(), json_num(*v))).collect::<serde_json::Map<_, _>>(),
            "equations": res.equations.iter().map(|q| json!({"label": q.label, "lhs": e(q.lhs), "rhs": e(q.rhs)})).collect::<Vec<_>>(),
            "unknowns": res.unknowns,
            "symbolic": res.symbolic.as_ref().map(|s| res.unknowns.iter().zip(s).map(|(n, &x)| (n.clone(), e(x))).collect::<serde_json::Map<_, _>>()),
            "solutions": res.numeric.iter().map(|s| res.unknowns.iter().zip(s).map(|(n, &x)| (n.clone(), json_num(x))).collect::<serde_json::Map<_, _>>()).collect::<Vec<_>>(),
            "derived": derived.iter().map(|(n, s, v)| json!({"name": n, "expr": s.map(e), "values": v.iter().map(|&x| json_num(x)).collect::<Vec<_>>()})).collect::<Vec<_>>(),
            "checks": res.checks.iter().map(|c| json!({
                "name": c.name, "condition": c.condition, "parameter": c.parameter,
                "symbolic": c.symbolic.iter().map(|&x| e(x)).collect::<Vec<_>>(),
                "min": c.min.map(|(v, at)| json!({"value": json_num(v), "at": at.map(json_num)})),
                "max": c.max.map(|(v, at)| json!({"value": json_num(v), "at": at.map(json_num)})),
                "over": c.over,
                "forces_at_critical": c.forces_at_critical.iter().map(|(n, v)| (n.clone(), json_num(*v))).collect::<serde_json::Map<_, _>>(),
                "critical": c.critical.iter().map(|k| json!({
                    "value": json_num(k.value),
                    "forces": k.forces.iter().map(|(n, v)| (n.clone(), json_num(*v))).collect::<serde_json::Map<_, _>>(),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "notes": res.notes.iter().filter(|n| !n.starts_with("polar:")).collect::<Vec<_>>(),
        });
        return Ok(format!("{v:#}\n"));
    }
    let mut out = format!("{}\n\n", model.name);
    let inst: Vec<String> = res
        .instant
        .iter()
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    out += &format!("At {}:\n", inst.join(", "));
    for e in &res.equations {
        out += &format!("  {}:\n    {} = {}\n", e.label, show(e.lhs), show(e.rhs));
    }
    if let Some(sol) = &res.symbolic {
        out += "\nSolution:\n";
        for (n, &s) in res.unknowns.iter().zip(sol) {
            out += &format!("  {n} = {}\n", show(s));
        }
    }
    out += "\nValues:\n";
    for (k, sol) in res.numeric.iter().enumerate() {
        if res.numeric.len() > 1 {
            out += &format!("  solution {}:\n", k + 1);
        }
        for (n, v) in res.unknowns.iter().zip(sol) {
            out += &format!("    {n:<12} {v:.6e}\n");
        }
    }
    if !derived.is_empty() {
        out += "\nDerived quantities ([monitors]):\n";
        for (n, s, v) in &derived {
            let vals: Vec<String> = v.iter().map(|x| format!("{x:.6}")).collect();
            match s {
                Some(s) => out += &format!("  {n} = {} = {}\n", show(*s), vals.join(" or ")),
                None => out += &format!("  {n} = {}\n", vals.join(" or ")),
            }
        }
    }
    for c in &res.checks {
        out += &format!(
            "\nCheck `{}`: {} — solved for {}\n",
            c.name, c.condition, c.parameter
        );
        for &s in &c.symbolic {
            out += &format!("  {} = {}\n", c.parameter, show(s));
        }
        let at = |o: Option<f64>| match (&c.over, o) {
            (Some(name), Some(v)) => format!(" at {name} = {v:.6}"),
            _ => String::new(),
        };
        let sense = |n: &String, v: f64| {
            if model.friction_forces.contains(n) && v < 0.0 {
                " (negative: friction acts against the `tangent` it was drawn along; it opposes \
                 sliding, so the body starts to slide along +tangent)"
            } else if model.friction_forces.contains(n) && v > 0.0 {
                " (positive: friction acts along `tangent`; the body starts to slide along -tangent)"
            } else {
                ""
            }
        };
        let forces = |out: &mut String, forces: &[(String, f64)]| {
            for (n, v) in forces {
                *out += &format!("  at the critical value {n} = {v:.6e}{}\n", sense(n, *v));
            }
        };
        match (c.min, c.max, &c.over) {
            (Some((v, o)), Some((w, o2)), Some(_)) => {
                out += &format!("  smallest critical {} = {v:.6e}{}\n", c.parameter, at(o));
                out += &format!("  largest critical {} = {w:.6e}{}\n", c.parameter, at(o2));
                forces(&mut out, &c.forces_at_critical);
            }
            (Some(_), _, None) => {
                // Every critical value in the range, each with the forces there.
                for k in &c.critical {
                    out += &format!("  critical {} = {:.6e}\n", c.parameter, k.value);
                    forces(&mut out, &k.forces);
                }
            }
            _ => out += &format!("  no critical {} in the search range\n", c.parameter),
        }
    }
    for n in res.notes.iter().filter(|n| !n.starts_with("polar:")) {
        out += &format!("\nnote: {n}\n");
    }
    Ok(out)
}
