//! The no-table path of sweeps and ensembles: a run reduced to its `[sweep.measures]`
//! statistics, its last output point, the first occurrence of each event, its drift check,
//! warnings, status and where its output stopped being finite, without building the output
//! table.
//!
//! [`super::run`] tabulates every output point (time, state, every output column) and then
//! evaluates the conservation scales and, in a sweep, the measures, each from the same state:
//! three solves for the accelerations and reactions per point, and a row allocated for each.
//! [`measure`] solves once per output point and feeds the one observation input to the
//! output columns (the drift check and the non-finite warning need them), the conservation
//! scales and the measures; when none of them reads an acceleration or a reaction, it does not
//! solve at all (the programs read only `[t, q, q', parameters]`). The solver, its output
//! points and every evaluation are the same as the full path's, so the results are the same,
//! bit for bit (`tests/run.rs` and `tests/ensemble_no_table.rs` check it).

use super::sweep::statistic;
use super::{
    integrate, scale_of, EventReport, MonitorReport, Prepared, RunFailure, RunSettings, RunStatus,
    SimError,
};
use crate::options::RunOption;
use pdyn_mech::model::spec::Stat;
use pdyn_ode::{Direction, Solution};

/// What a sweep or an ensemble keeps of a run.
#[derive(Clone, Debug)]
pub struct Measured {
    /// The statistic of each measure over the output points (NaN without measures).
    pub measures: Vec<f64>,
    /// The last output point `(t, state)` (the table's last row's first columns); `None`
    /// when there is no output point.
    pub last: Option<(f64, Vec<f64>)>,
    /// Events in time order.
    pub events: Vec<EventReport>,
    /// `(t, state)` of the first occurrence of each of [`Prepared::events`], by index.
    pub first_hits: Vec<Option<(f64, Vec<f64>)>>,
    /// The table's columns ([`Prepared::columns`]) that held NaN or infinity, if any did.
    pub non_finite: Option<NonFinite>,
    /// Drift of each conserved quantity.
    pub monitors: Vec<MonitorReport>,
    /// The warnings [`super::run`] would give.
    pub warnings: Vec<String>,
    /// Why the integration stopped early.
    pub failure: Option<RunFailure>,
    /// How the run ended.
    pub status: RunStatus,
    /// Solver statistics.
    pub stats: pdyn_ode::Stats,
}

/// Runs a prepared model and reduces it to its measures (`stats[j]` of measure `j`), the
/// drift of its conserved quantities and its warnings: what [`super::run`] followed by the
/// statistics of the measures over its rows gives, without the rows.
pub fn measure(prep: &Prepared, set: &RunSettings, stats: &[Stat]) -> Result<Measured, SimError> {
    if let Some(h) = &prep.hybrid {
        return measure_hybrid(prep, h, set, stats);
    }
    let (sol, failure) = integrate(prep, set)?;
    let failure = match failure {
        Some(f) if matches!(f.error, pdyn_ode::OdeError::Interrupted { .. }) => {
            return Ok(interrupted(prep, &sol, f));
        }
        other => other,
    };
    let sys = &prep.system;
    let n_meas = prep.measures.as_ref().map_or(0, |m| m.len());
    let conserved: Vec<usize> = (0..prep.observer.len())
        .filter(|&j| prep.conserved[j])
        .collect();
    let points = sol.len();
    let mut input = Vec::new();
    // The columns, then the scales: the observer's trailing outputs (`super::observations`).
    let columns = prep.observer.len();
    let mut extra = vec![0.0; columns + prep.observer.trailing()];
    let mut scale_series = vec![Vec::with_capacity(points); prep.observer.trailing()];
    let mut meas_out = vec![0.0; n_meas];
    let mut series = vec![Vec::with_capacity(points); n_meas];
    let mut drifts: Vec<(f64, f64)> = Vec::with_capacity(conserved.len());
    let mut non_finite = NonFiniteScan::default();
    // Solve for the accelerations and reactions at each point only when something evaluated
    // here reads them (a reaction or an acceleration among the output columns, a scale or a
    // measure); the other programs give the same bits without them.
    let base = sys.inputs.len();
    let solve = [&prep.observer, &prep.scales]
        .into_iter()
        .chain(prep.measures.as_ref())
        .chain(prep.friction_power.as_ref())
        .any(|o| !o.reads_only_first(base));
    let mut watch = super::FrictionWatch::default();
    let mut push = super::PushWatch::default();
    for k in 0..points {
        let (t, y) = (sol.t[k], sol.y_at(k));
        if solve {
            sys.observation_input(t, y, &mut input);
        } else {
            sys.observation_input_without_unknowns(t, y, &mut input);
        }
        prep.observer.eval_with_trailing(&input, &mut extra);
        let (extra, scales) = extra.split_at(columns);
        watch.check(prep, &input, t);
        push.check(prep, t, extra);
        // The row `[t, y, extra]` the full path would tabulate.
        non_finite.row(t, std::iter::once(&t).chain(y).chain(extra).copied());
        if k == 0 {
            drifts.extend(conserved.iter().map(|&j| (extra[j], 0.0)));
        }
        for (d, &j) in drifts.iter_mut().zip(&conserved) {
            // As the full path's fold: NaN propagates.
            let dev = (extra[j] - d.0).abs();
            d.1 = if dev.is_nan() || d.1.is_nan() {
                f64::NAN
            } else {
                d.1.max(dev)
            };
        }
        for (s, &v) in scale_series.iter_mut().zip(scales) {
            s.push(v.abs());
        }
        if let Some(m) = &prep.measures {
            m.eval(&input, &mut meas_out);
            for (s, &o) in series.iter_mut().zip(&meas_out) {
                s.push(o);
            }
        }
    }
    let scales: Vec<f64> = if points == 0 {
        vec![f64::NAN; scale_series.len()]
    } else {
        scale_series.into_iter().map(scale_of).collect()
    };
    let t_last = sol.t.last().copied().unwrap_or(0.0);
    let non_finite = non_finite.finish();
    let (events, monitors, mut warnings, status) = report(
        prep,
        &sol,
        set,
        &failure,
        &drifts,
        &scales,
        t_last,
        non_finite.is_some(),
    );
    warnings.extend(watch.warnings(prep));
    warnings.extend(push.warnings(prep));
    let mut first_hits = vec![None; prep.events.len()];
    for h in &sol.events {
        if let Some(slot @ None) = first_hits.get_mut(h.index) {
            *slot = Some((h.t, h.y.clone()));
        }
    }
    let last = points
        .checked_sub(1)
        .map(|k| (sol.t[k], sol.y_at(k).to_vec()));
    let mut measures = vec![f64::NAN; n_meas];
    if prep.measures.is_some() {
        for (j, s) in series.iter().enumerate() {
            measures[j] = statistic(stats[j], &sol.t, s);
        }
    }
    Ok(Measured {
        measures,
        last,
        events,
        first_hits,
        non_finite,
        monitors,
        warnings,
        failure,
        status,
        stats: sol.stats.clone(),
    })
}

/// What an interrupted run keeps: where it stopped and the events it met, nothing reduced
/// from its outputs (its measures are NaN anyway, and Ctrl-C should not wait for a pass over
/// a long run's rows).
fn interrupted(prep: &Prepared, sol: &Solution, failure: RunFailure) -> Measured {
    let mut first_hits = vec![None; prep.events.len()];
    for h in &sol.events {
        if let Some(slot @ None) = first_hits.get_mut(h.index) {
            *slot = Some((h.t, h.y.clone()));
        }
    }
    let n_meas = prep.measures.as_ref().map_or(0, |m| m.len());
    Measured {
        measures: vec![f64::NAN; n_meas],
        last: sol.last().map(|(t, y)| (t, y.to_vec())),
        events: Vec::new(),
        first_hits,
        non_finite: None,
        monitors: Vec::new(),
        warnings: Vec::new(),
        failure: Some(failure),
        status: RunStatus::Failed,
        stats: sol.stats.clone(),
    }
}

/// [`measure`] of a hybrid model: the run with its table (a run switches between modes,
/// each with its own programs), reduced to what a sweep keeps; the measures are evaluated at
/// each row's time and state ([`super::hybrid::Hybrid::measures`]).
fn measure_hybrid(
    prep: &Prepared,
    h: &super::hybrid::Hybrid,
    set: &RunSettings,
    stats: &[Stat],
) -> Result<Measured, SimError> {
    let res = super::hybrid::run(prep, h, set)?;
    let n_state = prep.state_names.len();
    let params = prep.system.parameters();
    let mut measures = Vec::new();
    if let Some(m) = h.measures() {
        let mut series = vec![Vec::with_capacity(res.rows.len()); m.len()];
        let mut out = vec![0.0; m.len()];
        let mut input = Vec::new();
        for r in &res.rows {
            input.clear();
            input.extend_from_slice(&r[..1 + n_state]);
            input.extend_from_slice(&params);
            m.eval(&input, &mut out);
            for (s, &o) in series.iter_mut().zip(&out) {
                s.push(o);
            }
        }
        let ts: Vec<f64> = res.rows.iter().map(|r| r[0]).collect();
        measures = series
            .iter()
            .zip(stats)
            .map(|(s, &st)| statistic(st, &ts, s))
            .collect();
    }
    let mut first_hits = vec![None; prep.events.len()];
    for e in &res.events {
        if let Some(k) = prep.events.iter().position(|p| p.name == e.name) {
            if first_hits[k].is_none() {
                first_hits[k] = Some((e.t, e.state.clone()));
            }
        }
    }
    Ok(Measured {
        measures,
        last: res.rows.last().map(|r| (r[0], r[1..1 + n_state].to_vec())),
        events: res.events.clone(),
        first_hits,
        non_finite: NonFinite::of_rows(&res.rows),
        monitors: res.monitors.clone(),
        warnings: res.warnings.clone(),
        failure: res.failure.clone(),
        status: res.status,
        stats: res.stats.clone(),
    })
}

/// Where a run's table held NaN or infinity.
#[derive(Clone, Debug, PartialEq)]
pub struct NonFinite {
    /// The first output time whose row holds a value that is not finite.
    pub t: f64,
    /// Indices, among the table's columns ([`Prepared::columns`]), of every column that holds
    /// one, ascending.
    pub columns: Vec<usize>,
}

impl NonFinite {
    /// The error every front end reports for these columns (`non_finite`, exit code 1):
    /// `origin: the output column(s) `x`, `y` (first at t = …)`; `columns` names the table's
    /// columns.
    pub fn error(&self, origin: &str, columns: &[String]) -> crate::Error {
        let quoted: Vec<String> = self
            .columns
            .iter()
            .map(|&c| format!("`{}`", columns[c]))
            .collect();
        crate::Error::NonFinite {
            what: format!(
                "{origin}: the output column(s) {} (first at t = {:e})",
                quoted.join(", "),
                self.t
            ),
            components: self.columns.clone(),
        }
    }

    /// The non-finite values of a table ([`super::RunResult::rows`]), `None` if all are finite.
    pub fn of_rows(rows: &[Vec<f64>]) -> Option<NonFinite> {
        // The common case, every value finite, in one pass the compiler vectorizes: `0·x` is
        // 0 for a finite `x` and NaN for infinity or NaN.
        if rows
            .iter()
            .all(|r| r.iter().fold(0.0, |acc: f64, x| acc + 0.0 * x) == 0.0)
        {
            return None;
        }
        let mut scan = NonFiniteScan::default();
        for r in rows {
            scan.row(r[0], r.iter().copied());
        }
        scan.finish()
    }
}

/// [`NonFinite`] gathered row by row.
#[derive(Default)]
pub(crate) struct NonFiniteScan {
    pub(crate) first_t: Option<f64>,
    pub(crate) bad: Vec<bool>,
}

impl NonFiniteScan {
    /// One row (its time `t` and its cells, `t` first).
    pub(crate) fn row(&mut self, t: f64, cells: impl Iterator<Item = f64>) {
        for (j, x) in cells.enumerate() {
            if !x.is_finite() {
                if self.bad.len() <= j {
                    self.bad.resize(j + 1, false);
                }
                self.bad[j] = true;
                self.first_t.get_or_insert(t);
            }
        }
    }

    pub(crate) fn finish(self) -> Option<NonFinite> {
        let t = self.first_t?;
        let columns = (0..self.bad.len()).filter(|&j| self.bad[j]).collect();
        Some(NonFinite { t, columns })
    }
}

/// Events, drift reports, warnings and status of a run, shared by the full path
/// ([`super::tabulate`]) and [`measure`]. `drifts[k]`: the first value and the largest
/// deviation from it (NaN if any was NaN) of the `k`-th conserved output column, empty when
/// there is no output point; `scales[k]` its scale; `t_last` the last output time;
/// `non_finite` whether any output value (time, state, column) is not finite.
#[allow(clippy::too_many_arguments)]
pub(crate) fn report(
    prep: &Prepared,
    sol: &Solution,
    set: &RunSettings,
    failure: &Option<RunFailure>,
    drifts: &[(f64, f64)],
    scales: &[f64],
    t_last: f64,
    non_finite: bool,
) -> (Vec<EventReport>, Vec<MonitorReport>, Vec<String>, RunStatus) {
    let events = sol
        .events
        .iter()
        .map(|h| EventReport {
            name: prep
                .events
                .get(h.index)
                .map_or("event".into(), |e| e.name.clone()),
            t: h.t,
            state: h.y.clone(),
            rising: h.direction == Direction::Rising,
        })
        .collect();
    let mut monitors = Vec::new();
    let mut warnings = Vec::new();
    let names = prep
        .observer
        .names
        .iter()
        .zip(&prep.conserved)
        .filter(|(_, &c)| c)
        .map(|(name, _)| name);
    for (name, &(first, dev)) in names.zip(drifts) {
        let k = monitors.len();
        let scale = scales.get(k).copied().unwrap_or(f64::NAN);
        let relative = scale > 0.0;
        let drift = if relative { dev / scale } else { dev };
        if drift.is_nan() {
            warnings.push(format!(
                "{name} should be conserved but is not finite (NaN or infinite) along the run: \
                 this result cannot be trusted; look for a division by zero or a function \
                 outside its domain in the model"
            ));
        } else if drift > set.drift_tolerance {
            warnings.push(format!(
                "{name} should be conserved but drifted by {drift:.3e} ({}) over t = 0..{t_last}: \
                 this result cannot be trusted (the First Law of Scientific Computing). Tighten \
                 the tolerance (e.g. {}) or use a symplectic method ({} {}).",
                if relative { "relative" } else { "absolute" },
                RunOption::Rtol.with(format!(
                    "{:.0e}",
                    (set.rtol.unwrap_or(1e-6) * 1e-3).max(1e-13)
                )),
                RunOption::Method.with("symplectic"),
                RunOption::Dt.with("..."),
            ));
        }
        monitors.push(MonitorReport {
            name: name.clone(),
            initial: first,
            drift,
            relative,
            scale,
            conserved: true,
        });
    }
    if non_finite && failure.is_none() {
        warnings.push("some output values are not finite (NaN or infinity)".into());
    }
    for miss in &sol.possible_misses {
        let name = prep
            .events
            .get(miss.index)
            .map_or("event", |e| e.name.as_str());
        warnings.push(format!(
            "event `{name}` may have crossed zero twice between t = {:.6e} and t = {:.6e} \
             unseen (its function came back towards zero and away within one step): limit the \
             step ({}) to be sure",
            miss.t_from,
            miss.t_to,
            RunOption::MaxStep
        ));
    }
    let status = match (failure, sol.status) {
        (Some(_), _) => RunStatus::Failed,
        (None, pdyn_ode::Status::Finished) => RunStatus::Finished,
        (None, pdyn_ode::Status::TerminalEvent(k)) => RunStatus::TerminalEvent(k),
    };
    (events, monitors, warnings, status)
}
