//! Parameter sweeps: one run per value of a parameter, in parallel on all cores (rayon),
//! reporting progress through a callback (the command line draws a bar with it). A failed run
//! is recorded with its message; it does not stop the others.

use super::measured::measure;
use super::{Prepared, RunFailure, RunSettings, SimError};
use pdyn_mech::model::spec::{Stat, SweepSpec};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Results of a sweep.
#[derive(Clone, Debug)]
pub struct SweepResult {
    /// The first (fastest varying) parameter.
    pub parameter: String,
    /// Its values.
    pub values: Vec<f64>,
    /// Measure names (`name` of each `[sweep.measures]` entry).
    pub measures: Vec<String>,
    /// One slice per combination of the other parameters (`[sweep.also]`); a single slice when
    /// only one parameter is swept.
    pub slices: Vec<Slice>,
    /// `(parameter values, problem)` of the runs that failed or warned.
    pub problems: Vec<(Vec<(String, f64)>, RunProblem)>,
    /// Number of runs.
    pub runs: usize,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Threads used.
    pub threads: usize,
}

/// Largest number of runs one sweep may ask for (the product of the swept values' counts):
/// the same bound as one parameter's values, checked when the model is loaded.
pub const MAX_SWEEP_RUNS: usize = pdyn_mech::model::spec::MAX_SWEEP_VALUES;

/// What went wrong with one run of a sweep (the others go on).
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum RunProblem {
    /// The run could not start.
    NotRun(SimError),
    /// The integration stopped early.
    Stopped(RunFailure),
    /// It finished with warnings (a drifting conserved quantity...).
    Warnings(Vec<String>),
}

impl std::fmt::Display for RunProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunProblem::NotRun(e) => write!(f, "{e}"),
            RunProblem::Stopped(e) => write!(f, "{e}"),
            RunProblem::Warnings(w) => f.write_str(&w.join("; ")),
        }
    }
}

/// The runs over the first parameter with the other parameters fixed.
#[derive(Clone, Debug)]
pub struct Slice {
    /// The other parameters' values (empty for a one-parameter sweep).
    pub fixed: Vec<(String, f64)>,
    /// `table[k][j]`: measure `j` of the run at `values[k]` (NaN when the run failed).
    pub table: Vec<Vec<f64>>,
}

/// Applies a statistic to a time series.
pub fn statistic(stat: Stat, t: &[f64], x: &[f64]) -> f64 {
    if x.is_empty() {
        return f64::NAN;
    }
    match stat {
        Stat::Max => x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        Stat::Min => x.iter().copied().fold(f64::INFINITY, f64::min),
        Stat::MaxAbs => x.iter().fold(0.0, |m, v| m.max(v.abs())),
        Stat::PeakToPeak => statistic(Stat::Max, t, x) - statistic(Stat::Min, t, x),
        Stat::Final => x[x.len() - 1],
        Stat::Mean | Stat::Rms => {
            let span = t[t.len() - 1] - t[0];
            if x.len() < 2 || span <= 0.0 {
                return if stat == Stat::Mean { x[0] } else { x[0].abs() };
            }
            let f = |v: f64| if stat == Stat::Mean { v } else { v * v };
            let integral: f64 = (1..x.len())
                .map(|k| 0.5 * (f(x[k]) + f(x[k - 1])) * (t[k] - t[k - 1]))
                .sum();
            if stat == Stat::Mean {
                integral / span
            } else {
                (integral / span).sqrt()
            }
        }
    }
}

/// Told after each run, from the worker that did it: `(runs done, runs in all)`.
pub type OnRun<'a> = &'a (dyn Fn(usize, usize) + Sync);

/// No progress reporting.
pub fn quiet(_: usize, _: usize) {}

/// Runs the sweep: every value of the first parameter for every combination of the others.
pub fn sweep(
    prep: &Prepared,
    set: &RunSettings,
    spec: &SweepSpec,
    stats: &[Stat],
    on_run: OnRun<'_>,
) -> Result<SweepResult, SimError> {
    set.validate()?;
    // Count the runs before building anything.
    let runs = spec
        .others
        .iter()
        .try_fold(spec.values.len(), |n, (_, v)| n.checked_mul(v.len()))
        .filter(|&n| n <= MAX_SWEEP_RUNS);
    if runs.is_none() {
        return Err(SimError::TooManySweepRuns {
            limit: MAX_SWEEP_RUNS,
        });
    }
    let start = crate::clock::Stopwatch::start();
    // Combinations of the other parameters (cartesian product).
    let mut combos: Vec<Vec<(usize, f64)>> = vec![Vec::new()];
    for (k, vals) in &spec.others {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                vals.iter().map(move |&v| {
                    let mut c2 = c.clone();
                    c2.push((*k, v));
                    c2
                })
            })
            .collect();
    }
    let jobs: Vec<(usize, f64)> = (0..combos.len())
        .flat_map(|ci| spec.values.iter().map(move |&v| (ci, v)))
        .collect();
    let done = AtomicUsize::new(0);
    let n_meas = prep.measures.as_ref().map_or(0, |m| m.len());
    let results: Vec<(Vec<f64>, Option<RunProblem>)> = jobs
        .par_iter()
        // Each worker owns a copy (the compiled programs keep per-call scratch space).
        .map_with(prep.clone(), |base, &(ci, v)| {
            let mut given = vec![(spec.parameter, v)];
            given.extend_from_slice(&combos[ci]);
            let p = base.with_parameters(&given);
            let out = measure_run(&p, set, stats, n_meas);
            on_run(done.fetch_add(1, Ordering::Relaxed) + 1, jobs.len());
            out
        })
        .collect();
    let name = |k: usize| prep.parameter_names.get(k).cloned().unwrap_or_default();
    let mut slices: Vec<Slice> = combos
        .iter()
        .map(|c| Slice {
            fixed: c.iter().map(|&(k, x)| (name(k), x)).collect(),
            table: Vec::with_capacity(spec.values.len()),
        })
        .collect();
    let mut problems = Vec::new();
    for (&(ci, v), (vals, prob)) in jobs.iter().zip(results) {
        slices[ci].table.push(vals);
        if let Some(p) = prob {
            let mut at = vec![(name(spec.parameter), v)];
            at.extend(slices[ci].fixed.iter().cloned());
            problems.push((at, p));
        }
    }
    Ok(SweepResult {
        parameter: name(spec.parameter),
        values: spec.values.clone(),
        measures: prep
            .measures
            .as_ref()
            .map(|m| m.names.clone())
            .unwrap_or_default(),
        slices,
        problems,
        runs: jobs.len(),
        seconds: start.seconds(),
        threads: rayon::current_num_threads(),
    })
}

/// One run and its measures, without its table (see [`super::measured`]).
fn measure_run(
    p: &Prepared,
    set: &RunSettings,
    stats: &[Stat],
    n_meas: usize,
) -> (Vec<f64>, Option<RunProblem>) {
    let res = match measure(p, set, stats) {
        Err(e) => return (vec![f64::NAN; n_meas], Some(RunProblem::NotRun(e))),
        Ok(r) => r,
    };
    if let Some(failure) = res.failure {
        // A statistic over the rows before a failure is not the run's: NaN, never a number
        // that looks like a result (the problem says where it stopped).
        return (vec![f64::NAN; n_meas], Some(RunProblem::Stopped(failure)));
    }
    let problem = (!res.warnings.is_empty()).then_some(RunProblem::Warnings(res.warnings));
    (res.measures, problem)
}

/// Peaks of each measure along the first parameter: `(measure name, [(at, value)])`.
pub type Peaks = Vec<(String, Vec<(f64, f64)>)>;

/// Local maxima of `y(x)` that stand above their neighbourhood: the resonance peaks of a
/// frequency sweep. Returned as `(x, y)`, refined by a parabola through the three samples.
pub fn peaks(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let max = y
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    for k in 1..y.len().saturating_sub(1) {
        let (a, b, c) = (y[k - 1], y[k], y[k + 1]);
        if b > a && b >= c && b > 0.05 * max {
            let denom = a - 2.0 * b + c;
            let shift = if denom.abs() > 0.0 {
                0.5 * (a - c) / denom
            } else {
                0.0
            };
            let h = x[k + 1] - x[k];
            out.push((x[k] + shift.clamp(-1.0, 1.0) * h, b));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_a_sine() {
        let t: Vec<f64> = (0..=1000)
            .map(|k| k as f64 * 2.0 * std::f64::consts::PI / 1000.0)
            .collect();
        let x: Vec<f64> = t.iter().map(|v| libm::sin(*v)).collect();
        assert!((statistic(Stat::MaxAbs, &t, &x) - 1.0).abs() < 1e-4);
        assert!(statistic(Stat::Mean, &t, &x).abs() < 1e-12);
        assert!((statistic(Stat::Rms, &t, &x) - 0.5f64.sqrt()).abs() < 1e-5);
        assert!((statistic(Stat::PeakToPeak, &t, &x) - 2.0).abs() < 1e-4);
    }

    #[test]
    fn peaks_are_refined() {
        let x: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|v| {
                1.0 / (1.0 + 50.0 * (v - 3.333).powi(2)) + 0.5 / (1.0 + 50.0 * (v - 7.0).powi(2))
            })
            .collect();
        let p = peaks(&x, &y);
        assert_eq!(p.len(), 2);
        assert!((p[0].0 - 3.333).abs() < 0.02, "{p:?}");
        assert!((p[1].0 - 7.0).abs() < 0.02, "{p:?}");
    }
}
