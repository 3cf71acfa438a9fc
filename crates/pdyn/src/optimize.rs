//! `pdyn optimize MODEL --maximize MEASURE --over theta=0..pi/2` (and Python's
//! `Model.optimize`): the parameter values within bounds that maximise (or minimise) one of
//! the model's `[sweep.measures]` (the same measures, statistics and compiled observers as
//! `pdyn sweep`; no second syntax).
//!
//! One parameter: Brent's method (golden section with parabolic steps, Brent 1973, ch. 5)
//! to a relative tolerance of 1e-10, then the stationary point refined as the root of the
//! measure's central-difference slope (step `1e-5` of the interval) by the same bracketing
//! Brent as `pdyn solve`'s: a maximum located from values alone cannot be closer than
//! about `sqrt(ε)` (the values are flat there), its slope's zero can. Several parameters:
//! Nelder–Mead on the box (points projected onto the bounds), from the box's centre.
//! Each evaluation is one run of the prepared model (`Prepared::with_parameters`, then
//! `measured::measure`): derived and compiled once.

use crate::error::Error;
use crate::sim::measured::measure;
use crate::sim::{self, Prepared, RunSettings};
use pdyn_mech::model::spec::Stat;

/// What to optimise.
#[derive(Clone, Debug)]
pub struct Goal {
    /// The measure's index among `[sweep.measures]`.
    pub measure: usize,
    /// Maximise (else minimise).
    pub maximize: bool,
    /// The parameters varied: (index in the model's parameters, lower, upper bound).
    pub over: Vec<(usize, f64, f64)>,
}

/// The optimum found.
#[derive(Clone, Debug)]
pub struct Optimum {
    /// The parameters' values, in the order of [`Goal::over`].
    pub x: Vec<f64>,
    /// The measure there.
    pub value: f64,
    /// Runs made.
    pub evaluations: usize,
    /// `brent` (1-D, with the slope's root when it brackets) or `nelder-mead`.
    pub method: &'static str,
    /// For one parameter: the measure's slope (central difference) at the optimum, and the
    /// width of the final bracket of its sign change (`None` when the optimum is at a bound
    /// or the slope did not change sign).
    pub slope_bracket: Option<(f64, f64)>,
    /// Whether the optimum is at a bound (within 1e-12 of the interval).
    pub at_bound: bool,
}

/// The measure at parameter values `x` (NaN when the run failed).
struct Objective<'a> {
    prep: &'a Prepared,
    set: &'a RunSettings,
    stats: &'a [Stat],
    goal: &'a Goal,
    evaluations: usize,
}

impl Objective<'_> {
    fn value(&mut self, x: &[f64]) -> f64 {
        self.evaluations += 1;
        let given: Vec<(usize, f64)> = self
            .goal
            .over
            .iter()
            .zip(x)
            .map(|(&(k, _, _), &v)| (k, v))
            .collect();
        let p = self.prep.with_parameters(&given);
        match measure(&p, self.set, self.stats) {
            Ok(m) if m.failure.is_none() => m
                .measures
                .get(self.goal.measure)
                .copied()
                .unwrap_or(f64::NAN),
            _ => f64::NAN,
        }
    }

    /// What is minimised: minus the measure when maximising; NaN (a failed run) is +inf.
    fn cost(&mut self, x: &[f64]) -> f64 {
        let v = self.value(x);
        let c = if self.goal.maximize { -v } else { v };
        if c.is_nan() {
            f64::INFINITY
        } else {
            c
        }
    }
}

/// Optimises `goal` over runs of `prep` with `set`; see the module documentation.
pub fn optimize(
    prep: &Prepared,
    set: &RunSettings,
    stats: &[Stat],
    goal: &Goal,
) -> Result<Optimum, Error> {
    set.validate()
        .map_err(|e| Error::argument("", e.to_string()))?;
    for &(_, lo, hi) in &goal.over {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::argument(
                "--over",
                format!("--over: the bounds {lo}..{hi} are not a finite interval with lo < hi"),
            ));
        }
    }
    let mut obj = Objective {
        prep,
        set,
        stats,
        goal,
        evaluations: 0,
    };
    if goal.over.len() == 1 {
        let (_, lo, hi) = goal.over[0];
        let (x, _) = pdyn_data::minimize::brent_min(
            &mut |x| obj.cost(&[x]),
            lo,
            hi,
            1e-10,
            1e-12 * (hi - lo),
        );
        let width = hi - lo;
        let at_bound = (x - lo).abs() <= 1e-12 * width.max(1.0) * 1e3
            || (hi - x).abs() <= 1e-12 * width.max(1.0) * 1e3;
        let mut best = x;
        let mut slope_bracket = None;
        if !at_bound {
            // The slope's zero: bracket it around x (a few tolerances out), then Brent.
            let h = 1e-5 * width;
            let mut slope = |t: f64| (obj.cost(&[t + h]) - obj.cost(&[t - h])) / (2.0 * h);
            let d = (1e-7 * width).max(4.0 * h);
            let (a, b) = ((x - d).max(lo + h), (x + d).min(hi - h));
            let (sa, sb) = (slope(a), slope(b));
            if sa.is_finite() && sb.is_finite() && sa < 0.0 && sb > 0.0 {
                let (l, r) = pdyn_mech::numeric_roots::brent_root(&mut slope, a, b, sa, sb);
                best = 0.5 * (l + r);
                slope_bracket = Some((l, r));
            }
        }
        let value = obj.value(&[best]);
        return Ok(Optimum {
            x: vec![best],
            value,
            evaluations: obj.evaluations,
            method: "brent",
            slope_bracket,
            at_bound,
        });
    }
    let x = nelder_mead(&mut obj, goal);
    let value = obj.value(&x);
    let at_bound = goal
        .over
        .iter()
        .zip(&x)
        .any(|(&(_, lo, hi), &v)| v <= lo || v >= hi);
    Ok(Optimum {
        x,
        value,
        evaluations: obj.evaluations,
        method: "nelder-mead",
        slope_bracket: None,
        at_bound,
    })
}

/// Nelder–Mead (reflection 1, expansion 2, contraction ½, shrink ½) on the box of
/// `goal.over`, every point projected onto it; from the centre with steps of a quarter of
/// each side; until the simplex's values agree to 1e-12 relative and its size is 1e-9 of
/// the box, or 400 iterations per parameter.
fn nelder_mead(obj: &mut Objective, goal: &Goal) -> Vec<f64> {
    let n = goal.over.len();
    let clamp = |x: &mut Vec<f64>| {
        for (v, &(_, lo, hi)) in x.iter_mut().zip(&goal.over) {
            *v = v.clamp(lo, hi);
        }
    };
    let centre: Vec<f64> = goal
        .over
        .iter()
        .map(|&(_, lo, hi)| 0.5 * (lo + hi))
        .collect();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    let c0 = obj.cost(&centre);
    simplex.push((centre.clone(), c0));
    for i in 0..n {
        let mut p = centre.clone();
        let (_, lo, hi) = goal.over[i];
        p[i] += 0.25 * (hi - lo);
        clamp(&mut p);
        let c = obj.cost(&p);
        simplex.push((p, c));
    }
    for _ in 0..400 * n {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, worst) = (simplex[0].1, simplex[n].1);
        let size = (1..=n)
            .flat_map(|k| {
                let s = &simplex;
                (0..n).map(move |i| {
                    let (_, lo, hi) = goal.over[i];
                    (s[k].0[i] - s[0].0[i]).abs() / (hi - lo)
                })
            })
            .fold(0.0f64, f64::max);
        if (worst - best).abs() <= 1e-12 * best.abs().max(1e-300) && size <= 1e-9 {
            break;
        }
        if size <= 1e-12 {
            break;
        }
        let mut mean = vec![0.0; n];
        for (p, _) in &simplex[..n] {
            for i in 0..n {
                mean[i] += p[i] / n as f64;
            }
        }
        let along = |t: f64| -> Vec<f64> {
            let mut p: Vec<f64> = (0..n)
                .map(|i| mean[i] + t * (simplex[n].0[i] - mean[i]))
                .collect();
            clamp(&mut p);
            p
        };
        let r = along(-1.0);
        let fr = obj.cost(&r);
        if fr < simplex[0].1 {
            let e = along(-2.0);
            let fe = obj.cost(&e);
            simplex[n] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (r, fr);
        } else {
            let c = if fr < simplex[n].1 {
                along(-0.5)
            } else {
                along(0.5)
            };
            let fc = obj.cost(&c);
            if fc < simplex[n].1.min(fr) {
                simplex[n] = (c, fc);
            } else {
                let b = simplex[0].0.clone();
                for vertex in simplex.iter_mut().skip(1) {
                    let mut p: Vec<f64> = b
                        .iter()
                        .zip(&vertex.0)
                        .map(|(bi, vi)| bi + 0.5 * (vi - bi))
                        .collect();
                    clamp(&mut p);
                    let f = obj.cost(&p);
                    *vertex = (p, f);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex.swap_remove(0).0
}

/// The goal of a model: the measure named `measure` among its `[sweep.measures]` and the
/// parameters `over` (name, lower, upper), as indices; located errors otherwise.
pub fn goal_of(
    model: &pdyn_mech::Model,
    measure: &str,
    maximize: bool,
    over: &[(String, f64, f64)],
    option: &str,
) -> Result<Goal, Error> {
    let measures: Vec<&str> = model
        .run
        .sweep
        .as_ref()
        .map(|s| s.measures.iter().map(|m| m.name.as_str()).collect())
        .unwrap_or_default();
    let Some(k) = measures.iter().position(|m| *m == measure) else {
        let have = if measures.is_empty() {
            "the model has no [sweep.measures]: declare one, e.g. range = { of = \"x\", stat = \"final\" }".to_string()
        } else {
            format!("its measures: {}", measures.join(", "))
        };
        return Err(Error::argument(
            option,
            format!("{option}: `{measure}` is not a measure of the model ({have})"),
        ));
    };
    let mut idx = Vec::new();
    for (name, lo, hi) in over {
        let Some(p) = model.parameters.iter().position(|q| &q.name == name) else {
            return Err(Error::argument(
                "--over",
                format!("--over: `{name}` is not a parameter of the model"),
            ));
        };
        if idx.iter().any(|&(q, _, _)| q == p) {
            return Err(Error::argument(
                "--over",
                format!("--over: `{name}` is given twice"),
            ));
        }
        idx.push((p, *lo, *hi));
    }
    if idx.is_empty() {
        return Err(Error::argument(
            "--over",
            "--over: name at least one parameter and its bounds (theta=0..pi/2)",
        ));
    }
    Ok(Goal {
        measure: k,
        maximize,
        over: idx,
    })
}

/// The statistics of the model's measures (what [`optimize`] needs beside the goal).
pub fn stats_of(model: &pdyn_mech::Model) -> Vec<Stat> {
    model
        .run
        .sweep
        .as_ref()
        .map_or(Vec::new(), |s| s.measures.iter().map(|m| m.stat).collect())
}

/// Prepares `model` (with the request's options) and optimises: what the CLI and Python call.
pub fn run(
    mut model: pdyn_mech::Model,
    req: &crate::request::Request,
    goal: &Goal,
) -> Result<Optimum, Error> {
    let set = sim::request::settings(&model, req)?;
    let mut prep = sim::request::prepare(&mut model, req.jit)?;
    if req.jit != sim::JitMode::Off {
        prep.make_observers_native();
    }
    let stats = stats_of(&model);
    optimize(&prep, &set, &stats, goal)
}
