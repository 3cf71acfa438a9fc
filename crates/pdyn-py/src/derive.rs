//! `Model.derive` and `Model.forces`: the equations of motion and the unknown forces of a
//! prescribed motion, as dicts of `(text, latex)` pairs (the Python layer builds the result
//! objects and their `_repr_latex_`).

use crate::errors::to_py;
use pdyn::Error;
use pdyn_expr::{Id, Pool};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The body of `Model.derive`: derives a clone of `model`, as `pdyn derive` does.
pub(crate) fn derive(py: Python<'_>, model: &pdyn_mech::Model) -> PyResult<PyObject> {
    let mut model = model.clone();
    let d =
        pdyn_mech::derive(&mut model, &pdyn_mech::DeriveOptions::default()).map_err(|error| {
            to_py(
                py,
                &Error::Derive {
                    origin: model.origin.clone(),
                    error,
                },
            )
        })?;
    // `M q'' = f` with entries collected and factored, as `pdyn derive` prints it
    // (`None` when some unknown is a reaction).
    let matrix = pdyn_mech::matrix_form::matrix_form(&mut model.pool, &d).map(|m| {
        let p = &mut model.pool;
        let mut entry = |x: &pdyn_mech::matrix_form::Entry| (x.render(p, false), x.render(p, true));
        let mass: Vec<Vec<(String, String)>> = (0..m.n)
            .map(|j| (0..m.n).map(|k| entry(&m.mass[j * m.n + k])).collect())
            .collect();
        let forcing: Vec<(String, String)> = m.forcing.iter().map(&mut entry).collect();
        (mass, forcing)
    });
    let p: &Pool = &model.pool;
    let e = |id: Id| (p.to_text(id), p.to_latex(id));
    let out = PyDict::new(py);
    let (mass, forcing) = matrix.unzip();
    out.set_item("mass_matrix", mass)?;
    out.set_item("forcing", forcing)?;
    let eqs: Vec<_> = d
        .equations
        .iter()
        .map(|q| (q.label.clone(), e(q.lhs), e(q.rhs)))
        .collect();
    out.set_item("equations", eqs)?;
    out.set_item(
        "unknowns",
        d.unknowns
            .iter()
            .map(|u| u.name.clone())
            .collect::<Vec<_>>(),
    )?;
    out.set_item(
        "solution",
        d.solution.as_ref().map(|s| {
            d.unknowns
                .iter()
                .zip(s)
                .map(|(u, &x)| (u.name.clone(), e(x)))
                .collect::<Vec<_>>()
        }),
    )?;
    out.set_item("state", d.state_names.clone())?;
    // d/dt q = q' for each free coordinate, then d/dt q' = the solved acceleration.
    let first_order = d.accelerations().map(|acc| {
        let n = d.free.len();
        let mut rows: Vec<(String, (String, String))> = Vec::new();
        for i in 0..n {
            let rate = &d.state_names[n + i];
            rows.push((d.state_names[i].clone(), (rate.clone(), rate.clone())));
        }
        for (i, &a) in acc.iter().enumerate() {
            rows.push((d.state_names[n + i].clone(), e(a)));
        }
        rows
    });
    out.set_item("first_order", first_order)?;
    out.set_item("notes", d.notes.clone())?;
    out.set_item("form", format!("{:?}", d.form).to_lowercase())?;
    // The names declared positive (masses, lengths, g): `to_sympy` gives their SymPy symbols
    // `positive=True`, so that expressions simplify against PyDy's as they do here.
    let positive: Vec<&str> = model
        .parameters
        .iter()
        .map(|q| q.name.as_str())
        .filter(|name| {
            p.find_symbol(name)
                .is_some_and(|s| p.symbol_info(s).positive)
        })
        .collect();
    out.set_item("positive", positive)?;
    Ok(out.into_any().unbind())
}

/// The body of `Model.forces`: solves `model` (its parameters applied) for the unknown forces
/// of its prescribed motion at the instant `at`, as `pdyn forces` does.
pub(crate) fn forces(
    py: Python<'_>,
    mut model: pdyn_mech::Model,
    at: Vec<(String, f64)>,
) -> PyResult<PyObject> {
    let opts = pdyn_mech::prescribed::ForcesOptions { at };
    let res = pdyn_mech::prescribed::solve_forces(&mut model, &opts).map_err(|error| {
        to_py(
            py,
            &Error::Forces {
                origin: model.origin.clone(),
                error,
            },
        )
    })?;
    let p: &Pool = &model.pool;
    let e = |id: Id| (p.to_text(id), p.to_latex(id));
    let out = PyDict::new(py);
    out.set_item("instant", res.instant.clone())?;
    out.set_item(
        "equations",
        res.equations
            .iter()
            .map(|q| (q.label.clone(), e(q.lhs), e(q.rhs)))
            .collect::<Vec<_>>(),
    )?;
    out.set_item("unknowns", res.unknowns.clone())?;
    out.set_item(
        "symbolic",
        res.symbolic
            .as_ref()
            .map(|s| s.iter().map(|&x| e(x)).collect::<Vec<_>>()),
    )?;
    out.set_item("numeric", res.numeric.clone())?;
    let checks = PyList::empty(py);
    for c in &res.checks {
        let d = PyDict::new(py);
        d.set_item("name", c.name.clone())?;
        d.set_item("condition", c.condition.clone())?;
        d.set_item("parameter", c.parameter.clone())?;
        d.set_item(
            "symbolic",
            c.symbolic.iter().map(|&x| e(x)).collect::<Vec<_>>(),
        )?;
        d.set_item("min", c.min)?;
        d.set_item("max", c.max)?;
        d.set_item("over", c.over.clone())?;
        d.set_item("forces_at_critical", c.forces_at_critical.clone())?;
        d.set_item(
            "critical",
            c.critical
                .iter()
                .map(|k| (k.value, k.forces.clone()))
                .collect::<Vec<_>>(),
        )?;
        checks.append(d)?;
    }
    out.set_item("checks", checks)?;
    out.set_item("notes", res.notes.clone())?;
    Ok(out.into_any().unbind())
}
