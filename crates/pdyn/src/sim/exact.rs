//! Closed-form solutions of a model's equations (issue 7's `dsolve`, applied to derived
//! equations): `pdyn derive` prints them, `pdyn run --method exact` evaluates them, and
//! `pdyn check` compares them with numerical integration.

use super::ClosedFormError;
use super::{tabulate, Prepared, RunResult, RunSettings};
use pdyn_expr::number::Number;
use pdyn_expr::{Id, Program};
use pdyn_mech::derive::{Derivation, UnknownKind};
use pdyn_mech::dsolve::{propagator, solve_system, ClosedForm, Propagator, Relation};
use pdyn_mech::model::CoordinateKind;
use pdyn_mech::{derive, DeriveOptions, Model};
use rustc_hash::FxHashMap;

/// The closed-form solution of a model, with the case that applies to its parameter values.
pub struct ExactSolution {
    /// Every case dsolve found.
    pub closed: ClosedForm,
    /// The case that applies to the parameter values.
    pub case: usize,
    /// Inputs `[t, parameters]`, outputs `[q1, q1', q2, q2', ...]` for that case.
    program: Program,
    /// The same solution at the parameter values, evaluated stably (near a resonance the
    /// formula cancels every digit); `None` when it cannot be built (then `program` serves).
    propagator: Option<(Vec<f64>, Propagator)>,
    /// Number of free coordinates.
    n: usize,
    /// The parameter values the solution was found at, when it holds for those only (a system
    /// solved numerically, see [`closed_form`]); `None` when it holds for any values.
    pub fixed_parameters: Option<Vec<f64>>,
}

/// Solves the model's equations of motion in closed form, when they are linear with constant
/// coefficients, for `pdyn check` and `pdyn run --method exact`. The error says why not
/// otherwise.
///
/// Accelerations solved symbolically give a closed form in the parameters' symbols, when
/// that takes at most [`CLOSED_FORM_WORK`]. Otherwise (more unknowns than the symbolic limit:
/// a 10-storey building, a 50-mass chain; or an elimination that swells: two coupled
/// oscillators with four symbolic parameters) `M q'' = f` is solved with numbers for the
/// parameters, which dsolve takes by the eigen-decomposition of `M` and `K`; that solution
/// holds for those values only (see [`ExactSolution::fixed_parameters`]).
pub fn closed_form(model: &mut Model) -> Result<ExactSolution, ClosedFormError> {
    closed_form_with(model, true)
}

/// The closed form in the parameters' symbols only (what `pdyn derive` prints): as
/// [`closed_form`], without solving at the parameter values.
pub fn symbolic_closed_form(model: &mut Model) -> Result<ExactSolution, ClosedFormError> {
    closed_form_with(model, false)
}

/// Most simplification work (see [`pdyn_expr::Pool::simplify_work`]) for a closed form in
/// symbols. The chapter's 2-storey building (symbols m, k) takes 120,000 units (20 ms), the
/// other examples under 2,000; a 2-storey building with its own m and k per storey took
/// 1.75 million (0.5–2 s) for a solution far too large to print.
pub const CLOSED_FORM_WORK: u64 = 400_000;

fn closed_form_with(model: &mut Model, at_values: bool) -> Result<ExactSolution, ClosedFormError> {
    if pdyn_mech::hybrid::is_hybrid(model) {
        return Err(ClosedFormError::Hybrid);
    }
    let d = derive(model, &DeriveOptions::default()).map_err(ClosedFormError::Derive)?;
    match d.accelerations() {
        Some(acc) => {
            let p = &mut model.pool;
            let equations = d
                .free
                .iter()
                .zip(&acc)
                .map(|(&ci, &a)| {
                    let qdd = p.coord(model.coordinates[ci].sym, 2);
                    p.sub(qdd, a)
                })
                .collect();
            match solve_equations(model, &d, equations, None, at_values) {
                // In symbols the numeric solvers do not apply either (a 50-mass chain with a
                // mass and a stiffness symbol each): with the values they may.
                Err(why @ (ClosedFormError::TooCostly { .. } | ClosedFormError::Dsolve(_)))
                    if at_values && !model.parameters.is_empty() =>
                {
                    match solve_at_values(model, &d) {
                        Ok(exact) => Ok(exact),
                        // Not linear, say: the reason given in symbols reads better.
                        Err(_) if !matches!(why, ClosedFormError::TooCostly { .. }) => Err(why),
                        Err(e) => Err(e),
                    }
                }
                r => r,
            }
        }
        None if !at_values => Err(ClosedFormError::NotSolved),
        None => solve_at_values(model, &d),
    }
}

/// `M q'' = f` solved with the parameters' values for their symbols.
fn solve_at_values(model: &mut Model, d: &Derivation) -> Result<ExactSolution, ClosedFormError> {
    let map = parameter_numbers(model);
    let equations = equations_at_values(model, d, &map)?;
    solve_equations(model, d, equations, Some(map), true)
}

/// dsolve on `equations` (the model's, `= 0`) with the model's initial conditions; in symbols
/// under [`CLOSED_FORM_WORK`] when `at_values` is `None`, else with the parameters' values
/// substituted by that map; with its stable evaluation at the parameter values when `stable`
/// (what a run needs; `pdyn derive` only prints).
fn solve_equations(
    model: &mut Model,
    d: &Derivation,
    equations: Vec<Id>,
    at_values: Option<FxHashMap<Id, Id>>,
    stable: bool,
) -> Result<ExactSolution, ClosedFormError> {
    let n = d.free.len();
    model.materialize_initials();
    let values: Vec<f64> = model.parameters.iter().map(|q| q.value).collect();
    let p = &mut model.pool;
    let mut coords = Vec::with_capacity(n);
    let mut initial = Vec::with_capacity(2 * n);
    for &ci in &d.free {
        let c = &model.coordinates[ci];
        coords.push(c.sym);
        if let CoordinateKind::Free { .. } = c.kind {
            if let Some(&(_, ie, re)) = model.initial_exprs.iter().find(|(i, _, _)| *i == ci) {
                let (ie, re) = match &at_values {
                    Some(map) => (p.subs(ie, map), p.subs(re, map)),
                    None => (ie, re),
                };
                initial.push((p.coord(c.sym, 0), ie));
                initial.push((p.coord(c.sym, 1), re));
            }
        }
    }
    let closed = if at_values.is_some() {
        solve_system(p, &equations, &coords, &initial)
    } else {
        let (closed, enough) = p.with_simplify_budget(CLOSED_FORM_WORK, |p| {
            solve_system(p, &equations, &coords, &initial)
        });
        if !enough {
            return Err(ClosedFormError::TooCostly {
                work: CLOSED_FORM_WORK,
            });
        }
        closed
    }
    .map_err(ClosedFormError::Dsolve)?;
    // With numeric parameter values, the right case is the one whose condition holds.
    let params: Vec<Id> = model.parameters.iter().map(|q| q.id).collect();
    let mut case = 0;
    for (k, c) in closed.cases.iter().enumerate() {
        let Some(cond) = c.condition else {
            case = k;
            break;
        };
        let prog = Program::compile(p, &params, &[cond.expr]).map_err(ClosedFormError::Compile)?;
        let mut ws = prog.workspace();
        let mut out = [0.0];
        prog.eval(&values, &mut ws, &mut out);
        let v = out[0];
        let holds = match cond.relation {
            Relation::Positive => v > 1e-12,
            Relation::Negative => v < -1e-12,
            Relation::Zero => v.abs() <= 1e-12,
        };
        if holds {
            case = k;
            break;
        }
    }
    let program = closed
        .compile(p, case, &params)
        .map_err(ClosedFormError::Dsolve)?;
    // The stable evaluation, with numbers for the parameters (already there at values).
    let propagator = if stable {
        let numbers = match &at_values {
            Some(_) => FxHashMap::default(),
            None => parameter_numbers_of(p, &model.parameters),
        };
        let numeric_equations: Vec<Id> = equations.iter().map(|&e| p.subs(e, &numbers)).collect();
        let numeric_initial: Vec<(Id, Id)> = initial
            .iter()
            .map(|&(l, v)| (l, p.subs(v, &numbers)))
            .collect();
        propagator(p, &numeric_equations, &coords, &numeric_initial)
            .ok()
            .map(|prop| (values.clone(), prop))
    } else {
        None
    };
    Ok(ExactSolution {
        closed,
        case,
        program,
        propagator,
        n,
        fixed_parameters: at_values.map(|_| values),
    })
}

/// Each parameter's leaf mapped to its value as a number.
fn parameter_numbers(model: &mut Model) -> FxHashMap<Id, Id> {
    parameter_numbers_of(&mut model.pool, &model.parameters)
}

fn parameter_numbers_of(
    p: &mut pdyn_expr::Pool,
    parameters: &[pdyn_mech::model::Parameter],
) -> FxHashMap<Id, Id> {
    parameters
        .iter()
        .map(|q| (q.id, p.num(Number::Float(q.value))))
        .collect()
}

/// `Σ_j A_ij q_j'' − b_i` for each row of the derived `A x = b`, with the parameters'
/// values for their symbols. Only when every unknown is an acceleration: reactions would
/// first have to be eliminated.
fn equations_at_values(
    model: &mut Model,
    d: &Derivation,
    map: &FxHashMap<Id, Id>,
) -> Result<Vec<Id>, ClosedFormError> {
    let columns = d
        .unknowns
        .iter()
        .map(|u| match u.kind {
            UnknownKind::Acceleration(ci) => Ok(model.coordinates[ci].sym),
            UnknownKind::Reaction(_) => Err(ClosedFormError::NotSolved),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let p = &mut model.pool;
    let accelerations: Vec<Id> = columns.iter().map(|&s| p.coord(s, 2)).collect();
    let m = columns.len();
    let mut equations = Vec::with_capacity(m);
    for i in 0..m {
        let mut terms = Vec::with_capacity(m + 1);
        for (j, &qdd) in accelerations.iter().enumerate() {
            let a = p.subs(d.system.a[i * m + j], map);
            terms.push(p.mul(&[a, qdd]));
        }
        let b = p.subs(d.system.b[i], map);
        terms.push(p.neg(b));
        equations.push(p.add(&terms));
    }
    Ok(equations)
}

impl ExactSolution {
    /// The state `[q, q']` at each time of `times`, row after row (parameters in model order;
    /// those of [`ExactSolution::fixed_parameters`] when it is set). At the parameter values
    /// the solution was built with, the stable evaluation (`exp(𝒜 t) z(0)`, see
    /// [`pdyn_mech::dsolve::propagator`]); else the formula.
    pub fn states(&self, times: &[f64], params: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut rows = Vec::with_capacity(times.len() * 2 * n);
        if let Some((values, prop)) = &self.propagator {
            if values.as_slice() == params && prop.coordinates() == n {
                let pairs = prop.sample(times);
                for row in pairs.chunks_exact(2 * n) {
                    rows.extend((0..n).map(|k| row[2 * k]));
                    rows.extend((0..n).map(|k| row[2 * k + 1]));
                }
                return rows;
            }
        }
        self.formula_states(times, params)
    }

    /// As [`ExactSolution::states`], always from the formula (what `pdyn derive` prints),
    /// however it cancels.
    pub fn formula_states(&self, times: &[f64], params: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut rows = Vec::with_capacity(times.len() * 2 * n);
        let mut ws = self.program.workspace();
        let mut input = Vec::with_capacity(1 + params.len());
        let mut out = vec![0.0; 2 * n];
        for &t in times {
            input.clear();
            input.push(t);
            input.extend_from_slice(params);
            self.program.eval(&input, &mut ws, &mut out);
            rows.extend((0..n).map(|k| out[2 * k]));
            rows.extend((0..n).map(|k| out[2 * k + 1]));
        }
        rows
    }

    /// Whether [`ExactSolution::states`] evaluates stably at `params` (else it evaluates the
    /// formula, which may cancel its digits near a resonance).
    pub fn is_stable_at(&self, params: &[f64]) -> bool {
        self.propagator
            .as_ref()
            .is_some_and(|(values, _)| values.as_slice() == params)
    }
}

/// `pdyn run --method exact`: the closed form evaluated at the output times, tabulated like
/// a numerical run (positions, reactions, monitors, drifts).
pub fn run_exact(
    prep: &Prepared,
    exact: &ExactSolution,
    set: &RunSettings,
) -> Result<RunResult, super::SimError> {
    set.validate()?;
    // The run's sampling, or 1001 points.
    let ts = set.output_times().unwrap_or_else(|| {
        RunSettings {
            points: Some(1001),
            ..set.clone()
        }
        .output_times()
        .unwrap_or_default()
    });
    let params = prep.system.parameters();
    // A solution found at the parameter values holds for those only; `prep` comes from the
    // same model, after the same `--set`.
    debug_assert!(exact
        .fixed_parameters
        .as_ref()
        .is_none_or(|fixed| *fixed == params));
    let n2 = 2 * exact.n;
    let sol = pdyn_ode::Solution {
        method: pdyn_ode::Method::Auto,
        n: n2,
        y: exact.states(&ts, &params),
        t: ts,
        events: Vec::new(),
        possible_misses: Vec::new(),
        stats: Default::default(),
        status: pdyn_ode::Status::Finished,
        dense: None,
    };
    let mut res = tabulate(prep, &sol, set, None);
    res.method = super::Solver::Exact;
    if let Some(w) = verify_against_integration(prep, &sol, set) {
        res.warnings.push(w);
    }
    Ok(res)
}

/// Largest difference, relative to the solution's size, that a closed form may have from a
/// tight numerical integration before it is reported as untrustworthy.
pub const EXACT_AGREEMENT: f64 = 1e-6;

/// The First Law applied to closed forms: a formula that is exact in exact arithmetic can lose
/// every digit in floating point (near a resonance, `F/(ωₙ² − ω²)` multiplies a difference of
/// nearly equal sines). Integrate with DOP853 at rtol 1e-11 at the same times and compare;
/// return a warning when they disagree by more than [`EXACT_AGREEMENT`].
fn verify_against_integration(
    prep: &Prepared,
    exact: &pdyn_ode::Solution,
    set: &RunSettings,
) -> Option<String> {
    let check = RunSettings {
        method: "dop853".into(),
        rtol: Some(1e-11),
        atol: Some(1e-12),
        dt: None,
        max_step: None,
        max_steps: None,
        points: None,
        output_dt: None,
        t_eval: Some(exact.t.clone()),
        ..set.clone()
    };
    let run = super::run(prep, &check).ok()?;
    if run.failure.is_some() || run.rows.len() != exact.len() {
        return None;
    }
    let n2 = exact.n;
    let mut worst = 0.0f64;
    for c in 0..n2 {
        let size = run.rows.iter().map(|r| r[1 + c].abs()).fold(0.0, f64::max);
        let err = (0..exact.len())
            .map(|k| (exact.y_at(k)[c] - run.rows[k][1 + c]).abs())
            .fold(0.0, f64::max);
        worst = worst.max(err / size.max(1e-300));
    }
    (worst > EXACT_AGREEMENT || worst.is_nan()).then(|| {
        format!(
            "the closed form differs from a DOP853 integration (rtol 1e-11) by {worst:.3e} relative \
             to the solution's size: evaluated in floating point it cannot be trusted here (near a \
             resonance or a repeated root the formula cancels large terms). Use a numerical method \
             (drop {}).",
            crate::options::RunOption::Method.with("exact")
        )
    })
}

/// Largest difference between a numerical run and the closed form, per state component.
#[derive(Clone, Debug)]
pub struct CheckReport {
    /// `(state name, max |numeric - exact|, max |exact|)`.
    pub errors: Vec<(String, f64, f64)>,
    /// When the exact solution was evaluated stably: the largest difference between it and
    /// the formula evaluated in floating point, relative to the [scale](CheckReport::scales)
    /// of each column. Tiny unless the formula cancels its terms (near a resonance).
    pub formula_gap: Option<f64>,
    /// The numerical run.
    pub run: RunResult,
}

impl CheckReport {
    /// The scale each state column's error is measured against: the largest `max |exact|`
    /// among the columns of the same derivative order (the coordinates together, the rates
    /// together) — the size of the whole state, not of the column alone. A column that stays
    /// near zero throughout (a node of a mode, at round-off) was compared with its own
    /// round-off and reported a relative error of 1.
    pub fn scales(&self) -> Vec<f64> {
        let order = |name: &str| name.len() - name.trim_end_matches('\'').len();
        self.errors
            .iter()
            .map(|(n, _, _)| {
                self.errors
                    .iter()
                    .filter(|(m, _, _)| order(m) == order(n))
                    .map(|e| e.2)
                    .fold(0.0, f64::max)
            })
            .collect()
    }

    /// Each column's `max |error|` relative to its [scale](CheckReport::scales) (0 when
    /// both are 0; the absolute error when the whole group is 0).
    pub fn relative_errors(&self) -> Vec<f64> {
        self.errors
            .iter()
            .zip(self.scales())
            .map(|((_, e, _), s)| if s > 0.0 { e / s } else { *e })
            .collect()
    }
}

/// `pdyn check`: integrates with `set` at the exact solution's sampling and compares.
pub fn check(
    prep: &Prepared,
    exact: &ExactSolution,
    set: &RunSettings,
) -> Result<CheckReport, super::SimError> {
    let mut set = set.clone();
    if set.points.is_none() && set.output_dt.is_none() && set.t_eval.is_none() {
        set.points = Some(1001);
    }
    let run = super::run(prep, &set)?;
    let params = prep.system.parameters();
    // A solution found at the parameter values holds for those only; `prep` comes from the
    // same model, after the same `--set`.
    debug_assert!(exact
        .fixed_parameters
        .as_ref()
        .is_none_or(|fixed| *fixed == params));
    let n2 = 2 * exact.n;
    let times: Vec<f64> = run.rows.iter().map(|r| r[0]).collect();
    let states = exact.states(&times, &params);
    let mut errors: Vec<(String, f64, f64)> = prep
        .state_names
        .iter()
        .map(|s| (s.clone(), 0.0, 0.0))
        .collect();
    for (row, y) in run.rows.iter().zip(states.chunks_exact(n2)) {
        for k in 0..n2 {
            let e = (row[1 + k] - y[k]).abs();
            errors[k].1 = errors[k].1.max(e);
            errors[k].2 = errors[k].2.max(y[k].abs());
        }
    }
    let mut report = CheckReport {
        errors,
        run,
        formula_gap: None,
    };
    if exact.is_stable_at(&params) {
        let formula = exact.formula_states(&times, &params);
        let scales = report.scales();
        let gap = states
            .chunks_exact(n2)
            .zip(formula.chunks_exact(n2))
            .flat_map(|(a, b)| (0..n2).map(move |k| (k, (a[k] - b[k]).abs())))
            .map(|(k, d)| if scales[k] > 0.0 { d / scales[k] } else { d })
            .fold(0.0, f64::max);
        report.formula_gap = Some(gap);
    }
    Ok(report)
}
