//! `pdyn.kin` and `pdyn.dsolve`: the computations of `pdyn kin` and `pdyn dsolve` (run with
//! the GIL released), returned as dicts of `(text, latex)` pairs and arrays (the Python layer,
//! `pdyn._symbolic`, builds the result objects).

use crate::convert::{f64_array, f64_matrix, quantity_py, tl};
use crate::errors::{guarded, input_error};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// `pdyn kin`'s computation: returns a dict of plain data (`pdyn.kin` builds the result).
#[pyfunction]
#[pyo3(signature = (position=None, polar=None, path=None, param="s".to_string(), speed="V".to_string(), at=Vec::new(), set=Vec::new(), max=None, over=None, signed=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _kin(
    py: Python<'_>,
    position: Option<String>,
    polar: Option<String>,
    path: Option<String>,
    param: String,
    speed: String,
    at: Vec<String>,
    set: Vec<String>,
    max: Option<String>,
    over: Option<String>,
    signed: Vec<String>,
) -> PyResult<PyObject> {
    let input = pdyn::kin::KinInput {
        position,
        polar,
        path,
        param,
        speed,
        at,
        set,
        max,
        over,
        signed,
    };
    guarded(py, || {
        let r = py
            .allow_threads(|| pdyn::kin::kin(&input))
            .map_err(|e| input_error(py, &e))?;
        let pool = &r.pool;
        let d = PyDict::new(py);
        d.set_item("variable", &r.variable)?;
        d.set_item("straight", r.straight)?;
        let qs = PyList::empty(py);
        for (name, q) in &r.quantities {
            qs.append((*name, quantity_py(py, pool, *q)?))?;
        }
        d.set_item("quantities", qs)?;
        let instants = PyList::empty(py);
        for i in &r.instants {
            let vals = PyList::empty(py);
            for (name, q, nums) in &i.values {
                vals.append((*name, quantity_py(py, pool, *q)?, nums.clone()))?;
            }
            instants.append((i.spec.clone(), i.resolved.clone(), vals))?;
        }
        d.set_item("instants", instants)?;
        match &r.max {
            None => d.set_item("max", py.None())?,
            Some(m) => {
                let md = PyDict::new(py);
                md.set_item("expr", &m.expr)?;
                md.set_item("over", &m.over)?;
                md.set_item("variable", &m.variable)?;
                match &m.found {
                    pdyn_mech::kinematics::Maximum::Numeric(e) => {
                        md.set_item("value", e.value)?;
                        md.set_item("at", e.at)?;
                        md.set_item("exact", false)?;
                        md.set_item("parameters", PyList::empty(py))?;
                    }
                    pdyn_mech::kinematics::Maximum::Exact {
                        at,
                        value,
                        parameters,
                    } => {
                        md.set_item("value", tl(pool, *value))?;
                        md.set_item("at", tl(pool, *at))?;
                        md.set_item("exact", true)?;
                        md.set_item("parameters", parameters.clone())?;
                    }
                }
                d.set_item("max", md)?;
            }
        }
        d.set_item("assumed_positive", r.assumed_positive.clone())?;
        Ok(d.into_any().unbind())
    })
}

/// `pdyn dsolve`'s computation: returns a dict of plain data (`pdyn.dsolve` builds the
/// result).
#[pyfunction]
#[pyo3(signature = (equations=Vec::new(), ic=None, rule=None, set=Vec::new(), at=Vec::new(), when=None, signed=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _dsolve(
    py: Python<'_>,
    equations: Vec<String>,
    ic: Option<String>,
    rule: Option<String>,
    set: Vec<String>,
    at: Vec<String>,
    when: Option<String>,
    signed: Vec<String>,
) -> PyResult<PyObject> {
    use pdyn::dsolve::Solved;
    use pdyn_mech::dsolve::{Method, Relation};
    let input = pdyn::dsolve::DsolveInput {
        equations,
        ic,
        rule,
        set,
        at,
        when,
        signed,
    };
    guarded(py, || {
        let r = py
            .allow_threads(|| pdyn::dsolve::dsolve(&input))
            .map_err(|e| input_error(py, &e))?;
        let pool = &r.pool;
        let d = PyDict::new(py);
        match &r.solved {
            Solved::Equations(s) => {
                let cf = &s.closed_form;
                d.set_item("kind", "equations")?;
                let coords: Vec<String> = cf
                    .coords
                    .iter()
                    .map(|&c| pool.name(c).to_string())
                    .collect();
                d.set_item("coords", coords.clone())?;
                d.set_item(
                    "method",
                    match cf.method {
                        Method::Exact => "exact",
                        Method::Numeric => "numeric",
                    },
                )?;
                d.set_item("residual", cf.residual)?;
                let cases = PyList::empty(py);
                for (ci, c) in cf.cases.iter().enumerate() {
                    let cd = PyDict::new(py);
                    let cond = c.condition.map(|k| {
                        (
                            tl(pool, k.expr),
                            match k.relation {
                                Relation::Positive => ">",
                                Relation::Zero => "=",
                                Relation::Negative => "<",
                            },
                        )
                    });
                    cd.set_item("condition", cond)?;
                    cd.set_item(
                        "solution",
                        coords
                            .iter()
                            .zip(&c.solution)
                            .map(|(n, &e)| (n.clone(), tl(pool, e)))
                            .collect::<Vec<_>>(),
                    )?;
                    cd.set_item("roots", c.roots.clone())?;
                    cd.set_item(
                        "constants",
                        c.constants
                            .iter()
                            .map(|&k| pool.to_text(k))
                            .collect::<Vec<_>>(),
                    )?;
                    match s.table.get(ci) {
                        Some(rows) => {
                            let w = 2 * coords.len();
                            let flat: Vec<f64> = rows.iter().flatten().copied().collect();
                            cd.set_item("values", f64_matrix(py, flat, rows.len(), w)?)?;
                        }
                        None => cd.set_item("values", py.None())?,
                    }
                    cases.append(cd)?;
                }
                d.set_item("cases", cases)?;
                d.set_item("times", f64_array(py, s.times.clone()))?;
                match &s.when {
                    None => d.set_item("when", py.None())?,
                    Some(w) => {
                        let wd = PyDict::new(py);
                        wd.set_item("condition", &w.condition)?;
                        wd.set_item("t", tl(pool, w.found.t))?;
                        wd.set_item("exact", w.found.exact)?;
                        wd.set_item("value", w.found.value)?;
                        wd.set_item(
                            "state",
                            w.found
                                .state
                                .iter()
                                .map(|st| (st.name.clone(), tl(pool, st.exact), st.value))
                                .collect::<Vec<_>>(),
                        )?;
                        d.set_item("when", wd)?;
                    }
                }
                d.set_item("assumed_positive", s.assumed_positive.clone())?;
            }
            Solved::Rule(s) => {
                d.set_item("kind", "rule")?;
                d.set_item("rule", &s.rule)?;
                d.set_item("variable", s.variable)?;
                d.set_item("points", f64_array(py, s.points.clone()))?;
                let qs = PyList::empty(py);
                for (q, vals) in s.solution.quantities.iter().zip(&s.values) {
                    let qd = PyDict::new(py);
                    qd.set_item("name", &q.name)?;
                    qd.set_item("closed", q.closed.map(|c| tl(pool, c)))?;
                    qd.set_item("describe", q.describe(pool))?;
                    qd.set_item(
                        "values",
                        f64_array(
                            py,
                            vals.iter()
                                .map(|v| v.as_ref().map_or(f64::NAN, |e| e.value))
                                .collect(),
                        ),
                    )?;
                    qd.set_item(
                        "errors",
                        f64_array(
                            py,
                            vals.iter()
                                .map(|v| v.as_ref().map_or(f64::NAN, |e| e.error))
                                .collect(),
                        ),
                    )?;
                    qd.set_item(
                        "messages",
                        vals.iter()
                            .map(|v| v.as_ref().err().map(ToString::to_string))
                            .collect::<Vec<_>>(),
                    )?;
                    qs.append(qd)?;
                }
                d.set_item("quantities", qs)?;
                d.set_item("assumed_positive", s.assumed_positive.clone())?;
            }
        }
        Ok(d.into_any().unbind())
    })
}
