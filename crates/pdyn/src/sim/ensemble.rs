//! Ensembles: one run per row of a table of parameter values (and initial values), in
//! parallel on clones of one [`Prepared`], each reduced by [`measure`] to what an ensemble
//! keeps (measures, final state, first event hits, drifts, status) without its table.
//!
//! The engine behind `pdyn.Model.ensemble` (and `pdyn.study`, which runs one chunk of rows per
//! call): the Python bindings resolve the settings, prepare (and cache) the model, call [`run`]
//! with the GIL released and turn the typed [`Ensemble`] into NumPy arrays. Nothing here knows
//! about Python.

use super::measured::measure;
use super::{Prepared, RunSettings};
use crate::Error;
use pdyn_mech::model::spec::Stat;

/// The rows of an ensemble: which parameters and state components each row sets, and their
/// values, row-major.
#[derive(Clone, Copy, Debug)]
pub struct Rows<'a> {
    /// Number of runs (rows).
    pub runs: usize,
    /// Names of the parameters set by each row; the model's values apply to the others.
    pub param_names: &'a [String],
    /// `runs × param_names.len()` values, row-major.
    pub params: &'a [f64],
    /// Names of the state components whose initial value each row sets.
    pub initial_names: &'a [String],
    /// `runs × initial_names.len()` values, row-major (empty without `initial_names`).
    pub initial: &'a [f64],
}

/// What one run of an ensemble keeps: its measures, final state, first event hits, monitor
/// drifts, status and the message of a problem.
#[derive(Clone, Debug)]
pub struct Member {
    /// The statistic of each measure (NaN when the run failed before any output).
    pub measures: Vec<f64>,
    /// Time of the last output point (NaN without one).
    pub t_final: f64,
    /// State at the last output point (NaN without one).
    pub final_state: Vec<f64>,
    /// `(t, state)` of each event's first occurrence.
    pub events: Vec<Option<(f64, Vec<f64>)>>,
    /// Drift of each conserved quantity (empty when the run failed before any output).
    pub drifts: Vec<f64>,
    /// Whether a drift exceeded the drift tolerance (or is NaN).
    pub drifted: bool,
    /// `RunStatus::code`, -1 for output that is not finite, -2 for a run that did not start.
    pub status: i32,
    /// Right-hand-side evaluations.
    pub nfev: usize,
    /// Why the run failed, if it did.
    pub message: Option<String>,
}

/// The names of an ensemble's measures, events, state components and conserved monitors:
/// the columns of the arrays built from its [`Member`]s.
#[derive(Clone, Debug, Default)]
pub struct Names {
    /// Measures (`[sweep.measures]` or those given with the call).
    pub measures: Vec<String>,
    /// Events.
    pub events: Vec<String>,
    /// State components.
    pub states: Vec<String>,
    /// Conserved monitors (the columns of the drifts).
    pub monitors: Vec<String>,
}

impl Names {
    /// The names of what an ensemble of `prep` reports.
    pub fn of(prep: &Prepared) -> Names {
        Names {
            measures: prep
                .measures
                .as_ref()
                .map(|m| m.names.clone())
                .unwrap_or_default(),
            events: prep.events.iter().map(|e| e.name.clone()).collect(),
            states: prep.state_names.clone(),
            monitors: prep
                .observer
                .names
                .iter()
                .zip(&prep.conserved)
                .filter(|(_, &c)| c)
                .map(|(n, _)| n.clone())
                .collect(),
        }
    }
}

/// An ensemble's results.
#[derive(Clone, Debug)]
pub struct Ensemble {
    /// What the columns of the members' values are.
    pub names: Names,
    /// One per row, in row order (none after a dry run).
    pub members: Vec<Member>,
    /// `(row, message)` of each row that failed (or, after a dry run, would fail).
    pub problems: Vec<(usize, String)>,
    /// Wall-clock time of the runs.
    pub seconds: f64,
    /// Threads that ran them (0 after a dry run).
    pub threads: usize,
}

impl Ensemble {
    /// The result of a dry run: only the problems.
    fn dry(problems: Vec<(usize, String)>, prep: &Prepared) -> Ensemble {
        Ensemble {
            names: Names::of(prep),
            members: Vec::new(),
            problems,
            seconds: 0.0,
            threads: 0,
        }
    }

    /// Gathers the members' problems.
    fn new(members: Vec<Member>, names: Names, seconds: f64, threads: usize) -> Ensemble {
        let problems = members
            .iter()
            .enumerate()
            .filter_map(|(r, o)| o.message.clone().map(|m| (r, m)))
            .collect();
        Ensemble {
            names,
            members,
            problems,
            seconds,
            threads,
        }
    }
}

/// Runs `prep` once per row of `rows`, in parallel: on a pool of `threads` threads, or on
/// rayon's global pool when `None`. `stats[j]` is the statistic of measure `j`. With
/// `dry_run`, only checks every row's parameters (finite, masses > 0) and returns the problems.
///
/// A name in `rows` that is not a parameter or a state component is an
/// [`Error::Argument`] (`params` / `initial`); a run that fails is a problem of the result,
/// not an error.
pub fn run(
    prep: Prepared,
    set: &RunSettings,
    stats: &[Stat],
    rows: &Rows<'_>,
    threads: Option<usize>,
    dry_run: bool,
) -> Result<Ensemble, Error> {
    let (runs, k) = (rows.runs, rows.param_names.len());
    let pidx = rows
        .param_names
        .iter()
        .map(|name| {
            prep.parameter_names
                .iter()
                .position(|p| p == name)
                .ok_or_else(|| {
                    Error::argument(
                        "params",
                        format!(
                            "`{name}` is not a parameter (parameters: {})",
                            prep.parameter_names.join(", ")
                        ),
                    )
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let sidx = rows
        .initial_names
        .iter()
        .map(|name| {
            prep.state_names
                .iter()
                .position(|p| p == name)
                .ok_or_else(|| {
                    Error::argument(
                        "initial",
                        format!(
                            "`{name}` is not a state component (state: {})",
                            prep.state_names.join(", ")
                        ),
                    )
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let defaults = prep.system.parameters();
    let derived = prep.derived.clone();
    let pvals = rows.params;
    // A row's parameters: the given ones, the model's values for the rest, and the derived
    // ones (`m = "4/3*pi*a^3*rho"`) recomputed unless given.
    let row_params = |r: usize| -> Vec<f64> {
        let mut v = defaults.clone();
        for (j, &i) in pidx.iter().enumerate() {
            v[i] = pvals[r * k + j];
        }
        derived.apply(&mut v, &pidx);
        v
    };
    if dry_run {
        let mut problems = Vec::new();
        for r in 0..runs {
            let v = row_params(r);
            if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                problems.push((r, format!("a parameter value is not finite ({x})")));
            } else if let Err(e) = prep.check_parameters(&v) {
                problems.push((r, e.to_string()));
            }
        }
        return Ok(Ensemble::dry(problems, &prep));
    }
    let ni = sidx.len();
    let ivals = rows.initial;
    let names = Names::of(&prep);
    let work = move || -> Vec<Member> {
        use rayon::prelude::*;
        (0..runs)
            .into_par_iter()
            .map_with(prep.clone(), |p, r| {
                p.set_parameters(&row_params(r));
                for (j, &i) in sidx.iter().enumerate() {
                    p.y0[i] = ivals[r * ni + j];
                }
                member(p, set, stats)
            })
            .collect()
    };
    let start = crate::clock::Stopwatch::start();
    let (members, threads) = match threads {
        Some(n) => {
            let pool = thread_pool(n)?;
            (pool.install(work), n.max(1))
        }
        None => (work(), rayon::current_num_threads()),
    };
    Ok(Ensemble::new(members, names, start.seconds(), threads))
}

/// Runs one member of an ensemble, without its table ([`measure`]: the same bits as
/// `sim::run`'s rows would give).
pub fn member(p: &Prepared, set: &RunSettings, stats: &[Stat]) -> Member {
    let n_states = p.state_names.len();
    let mut out = Member {
        measures: vec![f64::NAN; stats.len()],
        t_final: f64::NAN,
        final_state: vec![f64::NAN; n_states],
        events: vec![None; p.events.len()],
        drifts: Vec::new(),
        drifted: false,
        status: -2,
        nfev: 0,
        message: None,
    };
    let res = match measure(p, set, stats) {
        Ok(r) => r,
        Err(e) => {
            out.message = Some(e.to_string());
            return out;
        }
    };
    out.status = res.status.code();
    out.nfev = res.stats.fevals;
    out.message = res.failure.as_ref().map(|f| f.to_string());
    if let (None, Some(nf)) = (&res.failure, &res.non_finite) {
        out.status = -1;
        out.message = Some(nf.error("this run", &p.columns()).to_string());
    }
    if let Some((t, y)) = res.last {
        out.t_final = t;
        out.final_state.copy_from_slice(&y[..n_states]);
    }
    out.events = res.first_hits;
    for m in res.monitors.iter().filter(|m| m.conserved) {
        out.drifts.push(m.drift);
        if m.drift.is_nan() || m.drift > set.drift_tolerance {
            out.drifted = true;
        }
    }
    // A failed run's measures are NaN (statistics over the rows before the failure are not
    // the run's); its final state is where it stopped.
    if p.measures.is_some() && out.status >= 0 {
        out.measures = res.measures;
    }
    out
}

/// A rayon pool with `n` threads (at least one): the `threads=` of a sweep or an ensemble.
pub fn thread_pool(n: usize) -> Result<rayon::ThreadPool, Error> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n.max(1))
        .build()
        .map_err(|e| Error::argument("threads", format!("cannot start {n} threads: {e}")))
}
